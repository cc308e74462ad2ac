// A child process for the hardware-in-loop tests (tonusd, tonus-band-sim):
// spawned with its output in files, waited for with a timeout, killed at the
// end of the test whatever happened.
#pragma once

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <string>
#include <thread>
#include <vector>

#include "support/read_file.hpp"

extern char** environ;

namespace tonus::test {

class Process {
 public:
  // `out_path`: stdout and stderr go there.
  Process(const std::string& exe, const std::vector<std::string>& args, const std::string& out_path)
      : out_path_(out_path) {
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    std::vector<std::string> argv_s{exe};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    argv.reserve(argv_s.size() + 1);
    for (auto& s : argv_s) argv.push_back(s.data());
    argv.push_back(nullptr);
    ok_ = posix_spawn(&pid_, exe.c_str(), &fa, nullptr, argv.data(), environ) == 0;
    posix_spawn_file_actions_destroy(&fa);
  }
  ~Process() { kill(SIGKILL); }
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  [[nodiscard]] bool started() const { return ok_; }
  [[nodiscard]] pid_t pid() const { return pid_; }

  void kill(int sig) {
    if (pid_ > 0 && !reaped_) {
      ::kill(pid_, sig);
      if (sig == SIGKILL) wait(std::chrono::milliseconds(5000));
    }
  }
  // Exit status (128 + signal when killed), or -1 if still running after `timeout`.
  int wait(std::chrono::milliseconds timeout) {
    if (reaped_) return status_;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    do {
      int st = 0;
      if (::waitpid(pid_, &st, WNOHANG) == pid_) {
        reaped_ = true;
        status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
        return status_;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    } while (std::chrono::steady_clock::now() < deadline);
    return -1;
  }
  [[nodiscard]] std::string output() const { return read_file(out_path_); }

 private:
  std::string out_path_;
  pid_t pid_ = -1;
  bool ok_ = false;
  bool reaped_ = false;
  int status_ = -1;
};

}  // namespace tonus::test
