// A program started from a test as a child process: it dies with the test
// (even when the test is killed) and is terminated when it goes out of scope.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace stewart::test {

class ChildProcess {
 public:
  /// Starts `argv[0]` (a path) with the arguments `argv`.
  explicit ChildProcess(std::vector<std::string> argv);
  /// When still running: SIGTERM, up to 5 s to exit, then SIGKILL; reaped.
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  /// Whether the program could be started.
  bool started() const { return pid_ > 0; }
  /// Started and not (yet) exited.
  bool running();
  /// Its exit code, once it has exited: 128 + the signal when a signal
  /// ended it, -1 while it runs (or if it never started).
  int exit_code() const { return exit_code_; }

  /// Sends `signal` if it is still running.
  void Signal(int signal);
  /// Waits until it exits: its exit code.
  int Wait();
  /// Waits until it exits or `timeout` passes: its exit code, or -1.
  int Wait(std::chrono::steady_clock::duration timeout);
  /// Sends `signal` and waits until it exits: its exit code.
  int Stop(int signal);

 private:
  /// Reaps it if it has exited (blocking: waits for that).
  bool Reap(bool block);

  pid_t pid_ = -1;
  bool exited_ = false;
  int exit_code_ = -1;
};

}  // namespace stewart::test
