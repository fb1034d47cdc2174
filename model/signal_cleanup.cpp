#include "model/signal_cleanup.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <mutex>

namespace kanegen {

namespace {

constexpr int kSlots = 64;
constexpr int kPathMax = 4096;
struct Slot {
  std::atomic<bool> used{false};
  char path[kPathMax];
};
Slot g_slots[kSlots];
std::once_flag g_installed;

/// Removes a file, or a directory and the files directly in it, with system
/// calls only (async-signal-safe).
void remove_path(const char* path) {
  if (unlink(path) == 0) return;
  const int fd = open(path, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  alignas(8) char buf[4096];
  for (;;) {
    const long n = syscall(SYS_getdents64, fd, buf, sizeof buf);
    if (n <= 0) break;
    for (long off = 0; off < n;) {
      struct linux_dirent64 {
        unsigned long long d_ino;
        long long d_off;
        unsigned short d_reclen;
        unsigned char d_type;
        char d_name[];
      };
      auto* d = reinterpret_cast<linux_dirent64*>(buf + off);
      if (std::strcmp(d->d_name, ".") != 0 && std::strcmp(d->d_name, "..") != 0) unlinkat(fd, d->d_name, 0);
      off += d->d_reclen;
    }
  }
  close(fd);
  rmdir(path);
}

void on_signal(int sig) {
  for (Slot& s : g_slots)
    if (s.used.load()) remove_path(s.path);
  signal(sig, SIG_DFL);
  raise(sig);
}

void install() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction sa{};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    struct sigaction old{};
    sigaction(sig, nullptr, &old);
    if (old.sa_handler == SIG_IGN) continue;  // e.g. nohup: keep ignoring
    sigaction(sig, &sa, nullptr);
  }
}

}  // namespace

int register_cleanup(const std::string& path) {
  std::call_once(g_installed, install);
  if (path.size() + 1 > static_cast<std::size_t>(kPathMax)) return -1;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    // Claim the slot with the path not yet visible: write it, then publish.
    if (g_slots[i].used.load()) continue;
    std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
    if (g_slots[i].used.compare_exchange_strong(expected, true)) return i;
  }
  return -1;
}

void unregister_cleanup(int slot) {
  if (slot >= 0 && slot < kSlots) g_slots[slot].used.store(false);
}

}  // namespace kanegen
