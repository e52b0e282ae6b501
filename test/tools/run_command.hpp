// Runs a command line as a user would from a shell, for the tests of the command-line tools.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

#include "../text_contains.hpp"

namespace elo::test {

struct CommandResult {
  int exit_code = -1;   // -1 when the command did not exit normally (a signal)
  std::string output;   // stdout and stderr together
};

inline CommandResult runCommand(const std::string& command) {
  CommandResult result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  for (size_t read; (read = fread(buffer, 1, sizeof(buffer), pipe)) > 0;) result.output.append(buffer, read);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace elo::test
