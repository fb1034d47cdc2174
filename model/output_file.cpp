#include "model/output_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <random>
#include <streambuf>
#include <vector>

#include "model/diagnostics.hpp"
#include "model/signal_cleanup.hpp"

namespace kanegen {

namespace fs = std::filesystem;

namespace {

std::string errno_text(int e) { return std::strerror(e); }

}  // namespace

// named, not anonymous: OutputFile::Impl holds one (-Wsubobject-linkage in a unity batch)
namespace output_file_detail {

/// A streambuf writing to a file descriptor; remembers the first write error.
class FdBuf : public std::streambuf {
 public:
  explicit FdBuf(int fd) : fd_(fd), buf_(1 << 16) { setp(buf_.data(), buf_.data() + buf_.size()); }
  int error() const { return error_; }
  bool flush_all() { return flush_buffer() && error_ == 0; }

 protected:
  int_type overflow(int_type ch) override {
    if (!flush_buffer()) return traits_type::eof();
    if (!traits_type::eq_int_type(ch, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(ch);
      pbump(1);
    }
    return traits_type::not_eof(ch);
  }
  int sync() override { return flush_buffer() ? 0 : -1; }

 private:
  bool flush_buffer() {
    const char* p = pbase();
    std::size_t n = static_cast<std::size_t>(pptr() - pbase());
    while (n > 0 && error_ == 0) {
      const ssize_t w = ::write(fd_, p, n);
      if (w < 0) {
        if (errno == EINTR) continue;
        error_ = errno;
        break;
      }
      p += w;
      n -= static_cast<std::size_t>(w);
    }
    setp(buf_.data(), buf_.data() + buf_.size());
    return error_ == 0;
  }
  int fd_;
  std::vector<char> buf_;
  int error_ = 0;
};

}  // namespace output_file_detail
using output_file_detail::FdBuf;

namespace {

std::string directory_of(const std::string& path) {
  const fs::path p(path);
  return p.has_parent_path() ? p.parent_path().string() : std::string(".");
}

}  // namespace

void check_output_path(const std::string& path) {
  if (path.empty()) throw OutputRefused(path, "empty output path");
  struct stat st{};
  if (lstat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw OutputRefused(path, "is a directory; expected a file name");
    if (S_ISLNK(st.st_mode)) throw OutputRefused(path, "is a symbolic link; expected a regular file or a new name");
    if (!S_ISREG(st.st_mode))
      throw OutputRefused(path, "is not a regular file (a device, FIFO or socket); expected a regular file or a new name");
  } else if (errno != ENOENT) {
    throw OutputRefused(path, errno_text(errno));
  }
  const std::string dir = directory_of(path);
  struct stat ds{};
  if (stat(dir.c_str(), &ds) != 0) throw OutputRefused(path, "directory " + dir + " does not exist");
  if (!S_ISDIR(ds.st_mode)) throw OutputRefused(path, dir + " is not a directory");
  if (access(dir.c_str(), W_OK | X_OK) != 0) throw OutputRefused(path, "directory " + dir + " is not writable");
}

void check_output_option(const std::string& option, const std::string& path) {
  try {
    check_output_path(path);
  } catch (const OutputRefused& e) {
    const std::string why = std::string(e.what()).substr(e.path.size() + 2);
    throw InputError(Diagnostic{option, 0, "", fmt::format("cannot write '{}': {}", path, why)});
  }
}

void check_output_directory_option(const std::string& option, const std::string& dir) {
  auto refuse = [&](const std::string& why) {
    throw InputError(Diagnostic{option, 0, "", fmt::format("cannot write '{}': {}", dir, why)});
  };
  if (dir.empty()) refuse("empty output directory");
  std::error_code ec;
  fs::path p = fs::absolute(dir, ec).lexically_normal();
  if (ec) refuse(ec.message());
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec)) refuse("is not a directory; expected an output directory");
    if (access(p.c_str(), W_OK | X_OK) != 0) refuse("directory is not writable");
    return;
  }
  // created with its missing parents: the nearest existing ancestor must be a writable directory
  fs::path a = p;
  while (a.has_parent_path() && a != a.parent_path() && !fs::exists(a, ec)) a = a.parent_path();
  if (!fs::is_directory(a, ec)) refuse(a.string() + " is not a directory");
  if (access(a.c_str(), W_OK | X_OK) != 0) refuse("directory " + a.string() + " is not writable");
}

namespace {

/// The file a path names, for comparing two paths (symbolic links and ./.. resolved).
fs::path identity_of(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  return ec ? fs::absolute(path).lexically_normal() : p;
}

}  // namespace

void check_output_options(const std::vector<OutputOption>& outputs, const std::vector<std::string>& inputs) {
  std::vector<Diagnostic> faults;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const OutputOption& out = outputs[i];
    try {
      check_output_option(out.option, out.path);
    } catch (const InputError& e) {
      faults.insert(faults.end(), e.diagnostics().begin(), e.diagnostics().end());
      continue;
    }
    const fs::path id = identity_of(out.path);
    for (std::size_t j = 0; j < i; ++j)
      if (!outputs[j].path.empty() && identity_of(outputs[j].path) == id)
        faults.push_back(Diagnostic{out.option, 0, "",
                                    fmt::format("cannot write '{}': {} writes the same file; expected another file name",
                                                out.path, outputs[j].option)});
    for (const std::string& in : inputs)
      if (!in.empty() && identity_of(in) == id)
        faults.push_back(Diagnostic{out.option, 0, "",
                                    fmt::format("cannot write '{}': it is an input of this command ({}); expected "
                                                "another file name",
                                                out.path, in)});
  }
  if (!faults.empty()) throw InputError(faults);
}

struct OutputFile::Impl {
  int fd = -1;
  std::string named_tmp;  ///< fallback only: the named temporary
  int cleanup_slot = -1;
  mode_t mode = 0644;
  std::unique_ptr<FdBuf> buf;
  std::unique_ptr<std::ostream> os;
  bool committed = false;
};

OutputFile::OutputFile(const std::string& path) : path_(path), impl_(std::make_unique<Impl>()) {
  check_output_path(path);
  const std::string dir = directory_of(path);
  const mode_t um = umask(0);
  umask(um);
  impl_->mode = 0666 & ~um;
  struct stat st{};
  if (stat(path.c_str(), &st) == 0) impl_->mode = st.st_mode & 07777;  // keep an existing file's permissions
  impl_->fd = open(dir.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, impl_->mode);
  if (impl_->fd < 0) {  // no O_TMPFILE on this file system: a named temporary, cleaned on every exit path
    std::random_device rd;
    for (int attempt = 0; attempt < 100 && impl_->fd < 0; ++attempt) {
      impl_->named_tmp = path + ".kanegen-tmp-" + std::to_string(getpid()) + "-" + std::to_string(rd() % 1000000);
      impl_->fd = open(impl_->named_tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, impl_->mode);
      if (impl_->fd < 0 && errno != EEXIST) break;
    }
    if (impl_->fd < 0) throw OutputRefused(path, "cannot create a file in " + dir + ": " + errno_text(errno));
    impl_->cleanup_slot = register_cleanup(impl_->named_tmp);
  }
  impl_->buf = std::make_unique<FdBuf>(impl_->fd);
  impl_->os = std::make_unique<std::ostream>(impl_->buf.get());
}

OutputFile::~OutputFile() {
  if (!impl_) return;
  if (impl_->fd >= 0) ::close(impl_->fd);
  if (!impl_->committed && !impl_->named_tmp.empty()) ::unlink(impl_->named_tmp.c_str());
  unregister_cleanup(impl_->cleanup_slot);
}

std::ostream& OutputFile::stream() { return *impl_->os; }

void OutputFile::commit() {
  if (impl_->committed) return;
  impl_->os->flush();
  if (!impl_->buf->flush_all() || !*impl_->os)
    throw OutputFailed(path_ + ": write failed: " + errno_text(impl_->buf->error() ? impl_->buf->error() : EIO));
  if (fchmod(impl_->fd, impl_->mode) != 0 && impl_->named_tmp.empty()) {
    // an unnamed file's mode came from open(); a failure here changes nothing
  }
  // The target may have been replaced by something else meanwhile: check again.
  check_output_path(path_);
  // Block the signals that clean up while the file gets its name.
  sigset_t block, old;
  sigemptyset(&block);
  for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&block, s);
  pthread_sigmask(SIG_BLOCK, &block, &old);
  std::string error;
  if (impl_->named_tmp.empty()) {
    // Give the unnamed file a temporary name, then rename it over the target.
    const std::string proc = "/proc/self/fd/" + std::to_string(impl_->fd);
    std::string tmp;
    std::random_device rd;
    int rc = -1;
    for (int attempt = 0; attempt < 100 && rc != 0; ++attempt) {
      tmp = path_ + ".kanegen-tmp-" + std::to_string(getpid()) + "-" + std::to_string(rd() % 1000000);
      rc = linkat(AT_FDCWD, proc.c_str(), AT_FDCWD, tmp.c_str(), AT_SYMLINK_FOLLOW);
      if (rc != 0 && errno != EEXIST) break;
    }
    if (rc != 0) {
      error = "cannot link the written file: " + errno_text(errno);
    } else if (::close(impl_->fd) != 0) {
      error = "close failed: " + errno_text(errno);
      ::unlink(tmp.c_str());
    } else if (rename(tmp.c_str(), path_.c_str()) != 0) {
      error = "cannot rename into place: " + errno_text(errno);
      ::unlink(tmp.c_str());
    }
    impl_->fd = -1;
  } else {
    const int fd = impl_->fd;
    impl_->fd = -1;
    if (::close(fd) != 0) {
      error = "close failed: " + errno_text(errno);
    } else if (rename(impl_->named_tmp.c_str(), path_.c_str()) != 0) {
      error = "cannot rename into place: " + errno_text(errno);
    }
    if (!error.empty()) ::unlink(impl_->named_tmp.c_str());
  }
  if (error.empty()) impl_->committed = true;
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  if (!error.empty()) throw OutputFailed(path_ + ": " + error);
}

void write_file_atomically(const std::string& path, const std::string& content) {
  OutputFile f(path);
  f.stream() << content;
  f.commit();
}

}  // namespace kanegen
