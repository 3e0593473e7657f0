// Outputs written safely: through a unique temporary file that is never a planted symlink, in place
// on a device or FIFO, placed together by a transaction or not at all, and never onto an input or
// onto another output of the same run.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "kin2grf/error.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/io/text.hpp"
#include "test_support.hpp"

using namespace kin2grf;
namespace fs = std::filesystem;

namespace {
std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> n;
  for (const auto& e : fs::directory_iterator(dir)) n.push_back(e.path().filename().string());
  std::sort(n.begin(), n.end());
  return n;
}
}  // namespace

// Committed, the file holds what was written; abandoned (an exception on the way), the old file
// is untouched and no temporary file is left.
TEST(OutputFile, AnAtomicFileReplacesTheFileOnlyWhenCommitted) {
  const auto dir = test::temp_dir("atomic_file");
  const std::string path = (dir / "out.csv").string();
  write_file_text(path, "old\n");
  {
    AtomicFile f(path);
    f.stream() << "half of a new";
  }
  EXPECT_EQ(read_file_text(path), "old\n");
  {
    AtomicFile f(path);
    for (int i = 0; i < 100000; ++i) f.stream() << i << '\n';
    f.commit();
  }
  const std::string text = read_file_text(path);
  EXPECT_EQ(text.substr(0, 4), "0\n1\n");
  EXPECT_EQ(text.substr(text.size() - 6), "99999\n");
  EXPECT_EQ(names_in(dir), std::vector<std::string>{"out.csv"});
  EXPECT_THROW(AtomicFile((dir / "no such folder" / "out.csv").string()), InputError);
}

// The old fixed temporary name (OUT.kin2grf-tmp) was opened through a symlink planted there: the
// symlink's target was overwritten. The temporary file is now made with O_EXCL under a random name.
TEST(OutputFile, APlantedSymlinkAtTheOldTemporaryNameIsNeverFollowed) {
  const auto dir = test::temp_dir("planted_symlink");
  const std::string victim = (dir / "victim.c3d").string();
  write_file_text(victim, "precious");
  fs::create_symlink(victim, dir / "out.csv.kin2grf-tmp");
  write_file_text((dir / "out.csv").string(), "result\n");
  EXPECT_EQ(read_file_text(victim), "precious");
  EXPECT_EQ(read_file_text((dir / "out.csv").string()), "result\n");
  EXPECT_TRUE(fs::is_symlink(dir / "out.csv.kin2grf-tmp"));
}

// A FIFO (and so a device) is written in place: the old rename replaced it with a regular file.
TEST(OutputFile, AFifoIsWrittenInPlaceAndStaysAFifo) {
  const auto dir = test::temp_dir("fifo_output");
  const std::string fifo = (dir / "pipe").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string got;
  std::thread reader([&] {
    std::ifstream in(fifo);
    got.assign(std::istreambuf_iterator<char>(in), {});
  });
  write_file_text(fifo, "through the pipe\n");
  reader.join();
  EXPECT_EQ(got, "through the pipe\n");
  struct stat st {};
  ASSERT_EQ(::stat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_EQ(names_in(dir), std::vector<std::string>{"pipe"});
}

// /dev/full is a character device: writing fails with ENOSPC, said with the name, and the device
// is not replaced (it was, by a rename, when run as root).
TEST(OutputFile, ACharacterDeviceIsWrittenInPlaceAndAFullOneIsAnError) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  try {
    write_file_text("/dev/full", std::string(1 << 17, 'x'));
    FAIL() << "no error writing to /dev/full";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/full"), std::string::npos) << e.what();
  }
  struct stat st {};
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  write_file_text("/dev/null", "gone");
  ASSERT_EQ(::stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
}

// Inside a transaction nothing is placed before its commit; a run that fails on the way (the
// transaction destroyed uncommitted) leaves neither its outputs nor temporary files, and the files
// it would have replaced keep their old text. A nested transaction (a batch's trial) hands its
// files to the outer one.
TEST(OutputFile, ATransactionPlacesItsFilesTogetherOrNotAtAll) {
  const auto dir = test::temp_dir("transaction");
  const std::string a = (dir / "a.csv").string(), b = (dir / "b.json").string(), old = (dir / "old.mot").string();
  write_file_text(old, "old\n");
  {
    OutputTransaction run(true);
    write_file_text(a, "a\n");
    write_file_text(old, "new\n");
    EXPECT_FALSE(fs::exists(a));
    EXPECT_EQ(read_file_text(old), "old\n");
    // destroyed uncommitted: the run failed
  }
  EXPECT_EQ(names_in(dir), std::vector<std::string>{"old.mot"});
  EXPECT_EQ(read_file_text(old), "old\n");
  {
    OutputTransaction run(true);
    std::thread worker([&] {
      OutputTransaction trial;
      write_file_text(b, "b\n");
      trial.commit();
    });
    worker.join();
    write_file_text(a, "a\n");
    EXPECT_FALSE(fs::exists(b));
    run.commit();
  }
  EXPECT_EQ(read_file_text(a), "a\n");
  EXPECT_EQ(read_file_text(b), "b\n");
  EXPECT_EQ(names_in(dir), (std::vector<std::string>{"a.csv", "b.json", "old.mot"}));
  // Without a run's transaction (a library or Python caller), each worker's transaction places
  // its own files: a batch's trials on several threads never hand files to one another.
  std::vector<std::thread> workers;
  for (int w = 0; w < 4; ++w)
    workers.emplace_back([&, w] {
      OutputTransaction trial;
      write_file_text((dir / ("w" + std::to_string(w) + ".csv")).string(), "w\n");
      trial.commit();
    });
  for (auto& t : workers) t.join();
  for (int w = 0; w < 4; ++w) EXPECT_TRUE(fs::exists(dir / ("w" + std::to_string(w) + ".csv"))) << w;
}

// Two writers of one file (two runs at once) each rename a whole file of their own: the file is
// one of them, never a mixture, and no writer fails. The fixed temporary name mixed rows and made
// runs fail with "No such file or directory".
TEST(OutputFile, ConcurrentWritersOfOneFileNeverMixAndNeverFail) {
  const auto dir = test::temp_dir("concurrent_writers");
  const std::string path = (dir / "out.csv").string();
  std::vector<std::thread> writers;
  std::atomic<int> failures{0};
  for (int w = 0; w < 8; ++w)
    writers.emplace_back([&, w] {
      try {
        for (int round = 0; round < 20; ++round) {
          AtomicFile f(path);
          for (int i = 0; i < 2000; ++i) f.stream() << w << '\n';
          f.commit();
        }
      } catch (const InputError&) {
        ++failures;
      }
    });
  for (auto& t : writers) t.join();
  EXPECT_EQ(failures.load(), 0);
  const std::string text = read_file_text(path);
  ASSERT_EQ(text.size(), 4000u);
  EXPECT_EQ(text.find_first_not_of(std::string(1, text[0]) + "\n"), std::string::npos) << "mixed rows";
  EXPECT_EQ(names_in(dir), std::vector<std::string>{"out.csv"});
}

TEST(OutputFile, AnOutputGivenTwiceOrOntoAnInputIsRefusedByName) {
  const auto dir = test::temp_dir("outputs_twice");
  const std::string x = (dir / "x.csv").string();
  try {
    ensure_distinct_outputs({x, "", (dir / "." / "x.csv").string()}, {"--csv", "-o", "--json"});
    FAIL() << "the same output twice was accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("--csv"), std::string::npos) << m;
    EXPECT_NE(m.find("--json"), std::string::npos) << m;
  }
  EXPECT_NO_THROW(ensure_distinct_outputs({x, "", (dir / "y.csv").string(), ""}));
  write_file_text((dir / "in.c3d").string(), "c3d");
  fs::create_symlink(dir / "in.c3d", dir / "link.c3d");
  EXPECT_THROW(ensure_no_output_is_an_input({(dir / "link.c3d").string()}, {(dir / "in.c3d").string()}), InputError);
  EXPECT_NO_THROW(ensure_no_output_is_an_input({x}, {(dir / "in.c3d").string(), ""}));
}

TEST(OutputFile, AnOutputFolderThatIsAFileIsAnErrorNamingIt) {
  const auto dir = test::temp_dir("out_folder");
  const std::string file = (dir / "file").string();
  write_file_text(file, "x");
  try {
    ensure_output_folder(file);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos);
  }
  EXPECT_NO_THROW(ensure_output_folder((dir / "a" / "b").string()));
  EXPECT_TRUE(fs::is_directory(dir / "a" / "b"));
}

// ---------------------------------------------------------------------------------------------
// Inputs cut short while they are read (issue 31): the readers map their inputs, and a page past
// the file's new end used to stop the process with SIGBUS (18 crashes in 20 tries on a long TRC
// truncated 20 ms in). Now the read ends in an error naming the file.

#include <sys/types.h>

#include "kin2grf/io/opensim.hpp"
#include "kin2grf/synth/example.hpp"

TEST(InputFile, AMappedFileCutShortWhileReadIsAnErrorNotASignal) {
  const auto dir = test::temp_dir("mapped_truncated");
  const std::string path = (dir / "long.bin").string();
  write_file_text(path, std::string(std::size_t{1} << 20, 'k'));
  for (const bool populate : {false, true}) {
    write_file_text(path, std::string(std::size_t{1} << 20, 'k'));
    const MappedFile f(path, populate);
    EXPECT_FALSE(f.changed());
    ASSERT_EQ(::truncate(path.c_str(), 4096), 0);
    std::size_t ks = 0;
    for (const char c : f.text()) ks += c == 'k';  // every page, past the new end too
    EXPECT_EQ(ks, std::size_t{4096});  // zeros past the new end: the kernel dropped those pages
    EXPECT_TRUE(f.changed());
    try {
      f.ensure_unchanged();
      FAIL() << "no error";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(path), std::string::npos) << m;
      EXPECT_NE(m.find("changed while it was read"), std::string::npos) << m;
      EXPECT_NE(m.find("1048576 bytes when opened, 4096 now"), std::string::npos) << m;
    }
  }
}

// The TRC parser on a mapping whose file is cut to 4 KB as the parse begins: the change is the
// error, not what the parser made of the zeros.
TEST(InputFile, ATrcCutShortAsItIsParsedNamesTheChange) {
  const auto dir = test::temp_dir("trc_truncated");
  const std::string path = (dir / "walk.trc").string();
  SyntheticWalkOptions o;
  o.duration_s = 20;
  write_trc(path, make_example_walk(o).markers);
  const MappedFile f(path, false);
  try {
    f.read([&] {
      EXPECT_EQ(::truncate(path.c_str(), 4096), 0);
      return parse_trc(f.text(), path);
    });
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("changed while it was read"), std::string::npos) << e.what();
  }
}

// A file rewritten in place (same size, new text) while it is read is named as well.
TEST(InputFile, AFileRewrittenWhileReadIsNamed) {
  const auto dir = test::temp_dir("mapped_rewritten");
  const std::string path = (dir / "a.sto").string();
  write_file_text(path, std::string(10000, 'a'));
  const MappedFile f(path);
  {
    std::fstream out(path, std::ios::in | std::ios::out | std::ios::binary);
    out.seekp(100);
    out << "changed";
  }
  struct timespec times[2] = {{0, UTIME_OMIT}, {2000000000, 0}};
  ASSERT_EQ(::utimensat(AT_FDCWD, path.c_str(), times, 0), 0);
  EXPECT_TRUE(f.changed());
  EXPECT_THROW(f.ensure_unchanged(), InputError);
}
