#pragma once
// A program the tool starts for --mode actuators --plant hw (hw_bridge in
// bring-up mode, the device emulator), its output in a log file, stopped by
// its own pid (SIGTERM, then SIGKILL) when the tool is done.
#include <sys/types.h>

#include <string>
#include <vector>

namespace stewart::identify {

class ChildProcess {
 public:
  /// Starts argv[0] with argv; stdout and stderr go to log_path. Throws
  /// std::runtime_error when it cannot be started.
  ChildProcess(std::string name, const std::vector<std::string>& argv, std::string log_path);
  ~ChildProcess() { Stop(); }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  /// False once it has exited (exit_code() then says how).
  bool Running();
  /// SIGTERM, up to 3 s, then SIGKILL; returns its exit code (128 + signal
  /// when killed by one).
  int Stop();
  int exit_code() const { return exit_code_; }
  const std::string& name() const { return name_; }
  const std::string& log_path() const { return log_path_; }
  /// The last `lines` lines of its log, for an error message.
  std::string LogTail(int lines) const;

 private:
  void Reap(int status);

  std::string name_;
  std::string log_path_;
  pid_t pid_ = -1;
  int exit_code_ = -1;
};

}  // namespace stewart::identify
