// Runs a shell command for tests of executables: its combined output and exit status.
#pragma once

#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace maf_test {

/// Output (stdout and stderr) of @p command; @p exit_code receives its exit status (−1 if it did not exit).
inline std::string runCommand(const std::string& command, int* exit_code)
{
  std::string out;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr)
  {
    *exit_code = -1;
    return out;
  }
  char buf[512];
  while (fgets(buf, sizeof buf, pipe)) out += buf;
  const int status = pclose(pipe);
  *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

}  // namespace maf_test
