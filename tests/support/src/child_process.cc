#include "stewart/test_support/child_process.h"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <thread>

namespace stewart::test {

ChildProcess::ChildProcess(std::vector<std::string> argv) {
  if (argv.empty() || access(argv[0].c_str(), X_OK) != 0) return;
  std::vector<char*> args;
  for (std::string& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  pid_ = fork();
  if (pid_ == 0) {
    // Dies with the test, even when the test is killed: no stray process
    // keeps a port or a multicast group busy. SIGKILL, not SIGTERM: a child
    // the test had stopped (SIGSTOP, the fault suite) would keep a SIGTERM
    // pending forever.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    execv(args[0], args.data());
    _exit(127);
  }
}

ChildProcess::~ChildProcess() {
  if (!running()) return;
  Signal(SIGTERM);
  if (Wait(std::chrono::seconds(5)) < 0) Stop(SIGKILL);
}

bool ChildProcess::Reap(bool block) {
  if (pid_ <= 0 || exited_) return exited_;
  int status = 0;
  if (waitpid(pid_, &status, block ? 0 : WNOHANG) != pid_) return false;
  exited_ = true;
  exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return true;
}

bool ChildProcess::running() { return started() && !Reap(false); }

void ChildProcess::Signal(int signal) {
  if (running()) kill(pid_, signal);
}

int ChildProcess::Wait() {
  Reap(true);
  return exit_code_;
}

int ChildProcess::Wait(std::chrono::steady_clock::duration timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!Reap(false)) {
    if (!started() || std::chrono::steady_clock::now() >= end) return -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return exit_code_;
}

int ChildProcess::Stop(int signal) {
  Signal(signal);
  return Wait();
}

}  // namespace stewart::test
