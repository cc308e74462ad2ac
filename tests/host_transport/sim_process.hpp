// Runs tonus-band-sim as a child process wired to the test by socketpairs:
// the child's fd 3 is the HID link, fd 4 the CAN link (SOCK_SEQPACKET).
#pragma once

#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "tonus/host/transport/hid_transport.hpp"

extern char** environ;

namespace tonus::test {

class SimProcess {
 public:
  explicit SimProcess(std::vector<std::string> args) {
    int hid[2] = {-1, -1}, can[2] = {-1, -1};
    ::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, hid);
    ::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, can);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, hid[1], 3);  // dup2 clears close-on-exec
    posix_spawn_file_actions_adddup2(&fa, can[1], 4);
    std::vector<std::string> argv_s{TONUS_BAND_SIM};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    argv.reserve(argv_s.size() + 1);
    for (auto& s : argv_s) argv.push_back(s.data());
    argv.push_back(nullptr);
    ok_ = posix_spawn(&pid_, TONUS_BAND_SIM, &fa, nullptr, argv.data(), environ) == 0;
    posix_spawn_file_actions_destroy(&fa);
    ::close(hid[1]);
    ::close(can[1]);
    hid_fd_ = hid[0];
    can_fd_ = can[0];
  }
  ~SimProcess() {
    if (hid_fd_ >= 0) ::close(hid_fd_);
    if (can_fd_ >= 0) ::close(can_fd_);
    if (pid_ > 0 && !reaped_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  SimProcess(const SimProcess&) = delete;
  SimProcess& operator=(const SimProcess&) = delete;

  [[nodiscard]] bool started() const { return ok_; }
  // Hands the fd over (the transport closes it).
  int take_hid() { return std::exchange(hid_fd_, -1); }
  int take_can() { return std::exchange(can_fd_, -1); }
  void close_links() {
    if (hid_fd_ >= 0) ::close(std::exchange(hid_fd_, -1));
    if (can_fd_ >= 0) ::close(std::exchange(can_fd_, -1));
  }
  // Exit status, or -1 if it did not exit within the timeout (it is then killed).
  int wait(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        reaped_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return -1;
  }

 private:
  pid_t pid_ = -1;
  bool ok_ = false;
  bool reaped_ = false;
  int hid_fd_ = -1, can_fd_ = -1;
};

// Connects to a simulator's listening HID socket (--hid-socket), retrying for
// up to 2 s while the simulator starts; nullptr and `error` if it never came.
inline std::unique_ptr<host::SeqpacketHidTransport> connect_hid(const std::string& path, std::string& error) {
  std::unique_ptr<host::SeqpacketHidTransport> t;
  for (int k = 0; k < 200 && !t; ++k) {
    t = host::SeqpacketHidTransport::connect(path, error);
    if (!t) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return t;
}

}  // namespace tonus::test
