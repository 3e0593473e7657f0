#include "kin2grf/io/output_file.hpp"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <streambuf>
#include <unordered_map>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "kin2grf/error.hpp"

namespace kin2grf {

namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------------------------
// The temporary files being written, for the signal handler: a list that only grows, of nodes
// that are reused once free. The handler reads it without a lock (a signal may come while a
// thread holds any lock); a node's path is written before the node is marked live.
struct TempNode {
  std::atomic<int> state{0};  // 0 free, 1 being filled, 2 live (to remove on a signal)
  char path[4096] = {};
  std::atomic<TempNode*> next{nullptr};
};
std::atomic<TempNode*> temp_list{nullptr};

TempNode* register_temp(const std::string& path) {
  if (path.size() >= sizeof(TempNode::path)) return nullptr;  // mkstemps refuses such names first
  for (TempNode* n = temp_list.load(); n; n = n->next.load()) {
    int expected = 0;
    if (n->state.compare_exchange_strong(expected, 1)) {
      std::memcpy(n->path, path.c_str(), path.size() + 1);
      n->state.store(2);
      return n;
    }
  }
  auto* n = new TempNode;  // never freed: reused (the handler may be walking the list)
  n->state.store(1);
  std::memcpy(n->path, path.c_str(), path.size() + 1);
  n->state.store(2);
  TempNode* head = temp_list.load();
  do n->next.store(head);
  while (!temp_list.compare_exchange_weak(head, n));
  return n;
}

void unregister_temp(TempNode* n) {
  if (n) n->state.store(0);
}

extern "C" void remove_temps_and_reraise(int sig) {
  for (TempNode* n = temp_list.load(); n; n = n->next.load())
    if (n->state.load() == 2) ::unlink(n->path);  // unlink is async-signal-safe
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

/// The mode a new file gets (0666 less the umask), read once: umask() itself would change it for
/// every thread while it is read.
mode_t new_file_mode() {
  static const mode_t mode = [] {
    mode_t mask = 022;
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
      if (line.rfind("Umask:", 0) == 0) mask = static_cast<mode_t>(std::stoul(line.substr(6), nullptr, 8));
    return static_cast<mode_t>(0666 & ~mask);
  }();
  return mode;
}

/// An output stream buffer over a file descriptor (std::ofstream cannot take one): the temporary
/// file is written through the descriptor mkstemps opened, never reopened by name.
class FdBuf : public std::streambuf {
 public:
  explicit FdBuf(int fd) : fd_(fd), buf_(std::size_t{1} << 16) { setp(buf_.data(), buf_.data() + buf_.size()); }
  ~FdBuf() override { close_fd(); }
  int error() const { return error_; }
  /// Writes what is buffered and closes; false (error() says why) when any write failed.
  bool finish() {
    sync();
    if (fd_ >= 0 && ::close(fd_) != 0 && error_ == 0) error_ = errno;
    fd_ = -1;
    return error_ == 0;
  }

 protected:
  int_type overflow(int_type c) override {
    if (sync() != 0) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    if (n > epptr() - pptr()) {
      if (sync() != 0) return 0;
      if (n >= static_cast<std::streamsize>(buf_.size())) return write_all(s, static_cast<std::size_t>(n)) ? n : 0;
    }
    std::memcpy(pptr(), s, static_cast<std::size_t>(n));
    pbump(static_cast<int>(n));
    return n;
  }
  int sync() override {
    const auto n = static_cast<std::size_t>(pptr() - pbase());
    setp(buf_.data(), buf_.data() + buf_.size());
    return n == 0 || write_all(buf_.data(), n) ? 0 : -1;
  }

 private:
  bool write_all(const char* s, std::size_t n) {
    if (error_ != 0 || fd_ < 0) return false;
    while (n > 0) {
      const ssize_t w = ::write(fd_, s, n);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) {
        error_ = w < 0 ? errno : ENOSPC;
        return false;
      }
      s += w, n -= static_cast<std::size_t>(w);
    }
    return true;
  }
  void close_fd() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  int fd_ = -1;
  int error_ = 0;
  std::vector<char> buf_;
};

// The transactions: the innermost on each thread, and the process's outermost (the CLI's run),
// which worker threads with none of their own hand their files to.
thread_local OutputTransaction* thread_transaction = nullptr;
std::atomic<OutputTransaction*> root_transaction{nullptr};
std::mutex transaction_mutex;  // a transaction's list, added to from the batch's worker threads

void remove_quietly(const std::string& path) {
  std::error_code ec;
  fs::remove(path, ec);
}

/// 1 or 2 for a name of the process's standard output or error (/dev/stdout, /dev/fd/1,
/// /proc/self/fd/1, ...), else -1.
int standard_stream(const std::string& path) {
  if (path == "/dev/stdout" || path == "/dev/fd/1" || path == "/proc/self/fd/1") return 1;
  if (path == "/dev/stderr" || path == "/dev/fd/2" || path == "/proc/self/fd/2") return 2;
  return -1;
}

}  // namespace

struct AtomicFile::Impl {
  std::string path, temp;  // temp empty: written in place (a device or FIFO)
  std::unique_ptr<FdBuf> buf;
  std::unique_ptr<std::ostream> out;
  TempNode* node = nullptr;
  bool committed = false;
};

AtomicFile::AtomicFile(std::string path) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = std::move(path);
  if (m.path.empty()) throw InputError("an output file name is empty");
  struct stat st {};
  const bool exists = ::stat(m.path.c_str(), &st) == 0;  // follows a symlink: /dev/stdout is one
  if (exists && S_ISDIR(st.st_mode)) throw InputError(m.path + ": is a folder, not a file to write");
  int fd = -1;
  const int standard = standard_stream(m.path);
  if (standard >= 0) {
    // The process's own standard output or error, whatever it is connected to (a pipe, a
    // terminal, a file the shell opened): written through it.
    fd = ::fcntl(standard, F_DUPFD_CLOEXEC, 0);
    if (fd < 0) throw InputError(m.path + ": cannot write (" + std::strerror(errno) + ")");
  } else if (exists && !S_ISREG(st.st_mode)) {
    // A device, FIFO or terminal: written in place, never replaced by a regular file.
    fd = ::open(m.path.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) throw InputError(m.path + ": cannot open for writing (" + std::strerror(errno) + ")");
  } else {
    const fs::path target(m.path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    // (Appended, not "." + name: g++ 12 warns falsely on that concatenation, -Wrestrict.)
    std::string name(1, '.');
    name.append(target.filename().string()).append(".XXXXXX.kin2grf-tmp");
    std::string templ = (dir / name).string();
    fd = ::mkostemps(templ.data(), static_cast<int>(std::strlen(".kin2grf-tmp")), O_CLOEXEC);
    if (fd < 0) throw InputError(m.path + ": cannot open for writing (" + std::strerror(errno) + ")");
    m.temp = templ;
    m.node = register_temp(m.temp);
    // mkstemps makes the file 0600; the output gets the mode a new file would (or the replaced
    // file's own).
    ::fchmod(fd, exists ? (st.st_mode & 07777) : new_file_mode());
  }
  m.buf = std::make_unique<FdBuf>(fd);
  m.out = std::make_unique<std::ostream>(m.buf.get());
}

AtomicFile::~AtomicFile() {
  if (!impl_ || impl_->committed) return;
  impl_->out.reset();
  impl_->buf.reset();
  if (!impl_->temp.empty()) {
    remove_quietly(impl_->temp);
    unregister_temp(impl_->node);
  }
}

std::ostream& AtomicFile::stream() { return *impl_->out; }

void AtomicFile::commit() {
  Impl& m = *impl_;
  m.out->flush();
  const bool stream_ok = static_cast<bool>(*m.out);
  const bool ok = m.buf->finish() && stream_ok;
  if (!ok) {
    const int err = m.buf->error() != 0 ? m.buf->error() : EIO;
    throw InputError(m.path + ": write failed (" + std::strerror(err) + ")");
  }
  if (m.temp.empty()) {  // written in place
    m.committed = true;
    return;
  }
  OutputTransaction* t = thread_transaction ? thread_transaction : root_transaction.load();
  if (t) {
    t->add({m.temp, m.path});
  } else {
    std::error_code ec;
    fs::rename(m.temp, m.path, ec);
    if (ec) throw InputError(m.path + ": cannot replace the file (" + ec.message() + ")");
  }
  // From here the temporary file is the transaction's (or the target): not removed by ~AtomicFile.
  unregister_temp(m.node);
  if (t) m.node = nullptr;
  m.committed = true;
}

void write_file_text(const std::string& path, std::string_view text) {
  AtomicFile f(path);
  f.stream().write(text.data(), static_cast<std::streamsize>(text.size()));
  f.commit();
}

OutputTransaction::OutputTransaction(bool whole_run) : parent_(thread_transaction), previous_on_thread_(thread_transaction) {
  if (!parent_) {
    OutputTransaction* none = nullptr;
    if (whole_run && root_transaction.compare_exchange_strong(none, this)) root_ = true;
    else parent_ = root_transaction.load();  // the run's, on another thread; or none: standalone
  }
  thread_transaction = this;
}

void OutputTransaction::add(Pending p) {
  // Still removed on a signal while it waits for the commit.
  register_temp(p.temp);
  std::lock_guard lock(transaction_mutex);
  pending_.push_back(std::move(p));
}

namespace {
void unregister_temp_path(const std::string& path) {
  for (TempNode* n = temp_list.load(); n; n = n->next.load())
    if (n->state.load() == 2 && path == n->path) {
      n->state.store(0);
      return;
    }
}
}  // namespace

void OutputTransaction::commit() {
  std::vector<Pending> mine;
  {
    std::lock_guard lock(transaction_mutex);
    mine.swap(pending_);
  }
  committed_ = true;
  if (parent_) {
    for (auto& p : mine) {
      std::lock_guard lock(transaction_mutex);
      parent_->pending_.push_back(std::move(p));
    }
    return;
  }
  for (std::size_t k = 0; k < mine.size(); ++k) {
    std::error_code ec;
    fs::rename(mine[k].temp, mine[k].target, ec);
    if (ec) {
      const std::string what = mine[k].target + ": cannot replace the file (" + ec.message() + ")";
      for (std::size_t j = 0; j < k; ++j) remove_quietly(mine[j].target);  // what this run wrote
      for (std::size_t j = k; j < mine.size(); ++j) remove_quietly(mine[j].temp);
      for (const auto& p : mine) unregister_temp_path(p.temp);
      throw InputError(what);
    }
    unregister_temp_path(mine[k].temp);
  }
}

OutputTransaction::~OutputTransaction() {
  if (thread_transaction == this) thread_transaction = previous_on_thread_;
  if (root_) root_transaction.store(nullptr);
  if (committed_) return;
  std::lock_guard lock(transaction_mutex);
  for (const auto& p : pending_) {
    remove_quietly(p.temp);
    unregister_temp_path(p.temp);
  }
}

void install_output_cleanup_on_signals() {
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction sa {};
    sa.sa_handler = remove_temps_and_reraise;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND;
    ::sigaction(sig, &sa, nullptr);
  }
}

namespace {
/// The names a file is known by for the comparisons below: its normalised absolute path, and its
/// device and inode when it exists (a hard link or a symlink to it then matches too).
std::vector<std::string> file_keys(const std::string& path) {
  std::vector<std::string> keys;
  if (path.empty()) return keys;
  std::error_code ec;
  const auto canonical = fs::weakly_canonical(fs::absolute(path, ec), ec);
  keys.push_back("p:" + (ec ? path : canonical.string()));
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) keys.push_back("i:" + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino));
  return keys;
}
}  // namespace

bool same_file(const std::string& a, const std::string& b) {
  if (a.empty() || b.empty()) return false;
  const auto ka = file_keys(a), kb = file_keys(b);
  for (const auto& x : ka)
    for (const auto& y : kb)
      if (x == y) return true;
  return false;
}

void ensure_not_an_input(const std::string& output, const std::vector<std::string>& inputs) {
  ensure_no_output_is_an_input({output}, inputs);
}

void ensure_no_output_is_an_input(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs) {
  // Keyed, not pairwise: a batch of many trials compares every output with every input.
  std::unordered_map<std::string, const std::string*> known;
  for (const auto& in : inputs)
    for (auto& k : file_keys(in)) known.emplace(std::move(k), &in);
  for (const auto& out : outputs)
    for (const auto& k : file_keys(out))
      if (const auto it = known.find(k); it != known.end())
        throw InputError(out + ": is an input of this run (" + *it->second + "); refusing to overwrite it");
}

void ensure_output_folder(const std::string& dir) {
  if (dir.empty()) return;
  std::error_code ec;
  const auto st = fs::status(dir, ec);
  if (fs::exists(st) && !fs::is_directory(st)) throw InputError(dir + ": is a file, not a folder to write into");
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create the output folder (" + ec.message() + ")");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw InputError(dir + ": cannot write into the output folder (" + std::strerror(errno) + ")");
}

void ensure_distinct_outputs(const std::vector<std::string>& outputs, const std::vector<std::string>& what) {
  auto name = [&](std::size_t k) { return k < what.size() && !what[k].empty() ? what[k] + " " : std::string(); };
  std::unordered_map<std::string, std::size_t> seen;
  for (std::size_t j = 0; j < outputs.size(); ++j)
    for (auto& k : file_keys(outputs[j])) {
      const auto [it, fresh] = seen.emplace(std::move(k), j);
      if (!fresh && it->second != j) {
        const std::size_t i = it->second;
        throw InputError(outputs[j] + ": given twice as an output (" + name(i) + outputs[i] + " and " + name(j) + outputs[j] +
                         "); one would replace the other");
      }
    }
}

}  // namespace kin2grf
