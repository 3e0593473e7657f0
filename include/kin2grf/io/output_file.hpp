// kin2grf I/O: files written safely.
//
// What a run writes never replaces a file half way, never follows a planted symlink, never mixes
// with another run writing the same file, and is removed when the run fails:
// - A regular file (or a name that does not exist yet) is written to a temporary file of a unique
//   name made with mkstemp (O_CREAT | O_EXCL: an existing name, a symlink included, is never
//   opened) in the target's folder, then renamed over the target. Two runs writing one target each
//   rename a whole file of their own: the target is one of them, never a mixture.
// - A device, a FIFO or /dev/stdout (anything that exists and is not a regular file) is written in
//   place: renaming over /dev/null would replace the device with a file.
// - Inside an OutputTransaction the renames wait for the transaction's commit(); a run that fails
//   before it (an exception, a later output that cannot be written) leaves none of its outputs.
// - SIGINT, SIGTERM and SIGHUP remove the temporary files being written
//   (install_output_cleanup_on_signals()).
#pragma once

#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace kin2grf {

/// A file written through a unique temporary file in the target's folder, renamed over the target
/// by commit() (or by the enclosing OutputTransaction's commit()); a device or FIFO is written in
/// place. Written as it is made, so a long trial's output is never held whole in memory.
/// Destroyed uncommitted (an exception on the way), the temporary file is removed.
class AtomicFile {
 public:
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  std::ostream& stream();
  /// Flushes and checks that every write succeeded (InputError naming the file otherwise); then
  /// renames the temporary file over the target, or hands it to the current OutputTransaction.
  void commit();

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// Write through a temporary file renamed at the end (no half file on failure).
void write_file_text(const std::string& path, std::string_view text);

/// The outputs of one run (or of one trial of a batch), placed together or not at all. While one
/// is alive on a thread, AtomicFile::commit() on that thread hands it the finished temporary file
/// instead of renaming it; with none on the thread, the whole run's transaction (the CLI's) takes
/// it; with none at all (a library or Python caller), the file is renamed at once.
/// commit() of a nested transaction hands its files to the enclosing one; commit() of the
/// outermost renames them all. Destroyed uncommitted, it removes every temporary file it holds.
class OutputTransaction {
 public:
  /// `whole_run`: the process's outermost (a program's run, which worker threads hand their
  /// files to); otherwise nested in the thread's, or in the run's, or standalone when neither is.
  explicit OutputTransaction(bool whole_run = false);
  ~OutputTransaction();
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;
  /// InputError naming the file when one cannot be renamed; the files this commit had already
  /// placed are then removed, and so are the temporary files left.
  void commit();

  struct Pending {
    std::string temp, target;
  };
  void add(Pending p);

 private:
  std::vector<Pending> pending_;
  OutputTransaction* parent_ = nullptr;
  OutputTransaction* previous_on_thread_ = nullptr;
  bool committed_ = false;
  bool root_ = false;
};

/// SIGINT, SIGTERM and SIGHUP remove the temporary files of the outputs being written, then end
/// the process as the signal would have. For programs (the CLI), not for a host such as Python.
void install_output_cleanup_on_signals();

/// InputError when `output` is one of `inputs` (the same file by any name): an output never
/// overwrites a run's input.
void ensure_not_an_input(const std::string& output, const std::vector<std::string>& inputs);
/// The same for many outputs (a batch's), in time linear in their number and the inputs'.
void ensure_no_output_is_an_input(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs);
/// InputError when two of `outputs` (empty ones aside) are the same file by any name: one would
/// silently replace the other. `what` names them in the message ("--csv", "--json", ...), in order.
void ensure_distinct_outputs(const std::vector<std::string>& outputs, const std::vector<std::string>& what = {});
/// Creates `dir` (and its parents) as a folder to write outputs into: InputError naming it when it
/// is a file, cannot be created or cannot be written into.
void ensure_output_folder(const std::string& dir);
/// Whether two paths name the same file (existing or not): equivalent(), or the same normalised
/// absolute path.
bool same_file(const std::string& a, const std::string& b);

}  // namespace kin2grf
