// Output files that are either the complete new file or untouched: written
// to an unnamed temporary file (O_TMPFILE) in the target's directory and
// linked into place only by commit(); an OutputFile destroyed without
// commit() (an exception, a failed run) leaves nothing behind, and so does a
// process killed by any signal before the commit (the file has no name
// until then). Every write and the close are checked. A target that exists
// but is not a regular file (a directory, device, FIFO, socket or symlink) is
// refused, never replaced. Where O_TMPFILE is not available, a named
// temporary beside the target is used and removed on every exit path and on
// SIGINT/SIGTERM/SIGHUP (signal_cleanup.hpp).
#pragma once

#include <memory>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace kanegen {

/// The target cannot be written (refused before anything was written: not a
/// regular file, missing or unwritable directory). The CLI answers exit 2.
class OutputRefused : public std::runtime_error {
 public:
  OutputRefused(const std::string& path, const std::string& why)
      : std::runtime_error(path + ": " + why), path(path) {}
  std::string path;
};

/// Writing failed part-way (e.g. a full disk). Nothing was left behind.
class OutputFailed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class OutputFile {
 public:
  /// Throws OutputRefused.
  explicit OutputFile(const std::string& path);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  std::ostream& stream();
  /// Flushes, checks and links the file into place (replacing an older
  /// regular file). Throws OutputFailed; the target is then untouched.
  void commit();
  const std::string& path() const { return path_; }

 private:
  struct Impl;
  std::string path_;
  std::unique_ptr<Impl> impl_;
};

/// OutputFile with `content`, committed.
void write_file_atomically(const std::string& path, const std::string& content);

/// Throws OutputRefused unless `path` could be written: its directory exists
/// and is writable, and the path is absent or a regular file.
void check_output_path(const std::string& path);

/// check_output_path for the value of a command-line option: a refusal is an
/// InputError "OPTION: cannot write 'PATH': why" (exit 2).
void check_output_option(const std::string& option, const std::string& path);

/// An output directory (a sweep's -o): refused with an InputError naming
/// `option` when it is empty, exists and is not a directory (a file, e.g.
/// one of the command's inputs), is an unwritable directory, or would be
/// created under an ancestor that is not a writable directory.
void check_output_directory_option(const std::string& option, const std::string& dir);

/// One output of a command: the option that names it and its path.
struct OutputOption {
  std::string option, path;
};

/// Every output of one command, checked before any work (issue 34): each as
/// check_output_option (an empty path refused), two outputs on the same file
/// refused, and an output on one of `inputs` (the model, its modal files, a
/// state: what the command reads) refused. Throws InputError with one
/// diagnostic per fault, each naming its option.
void check_output_options(const std::vector<OutputOption>& outputs, const std::vector<std::string>& inputs);

}  // namespace kanegen
