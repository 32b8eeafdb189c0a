#include "output/shell_command.hpp"

#include <fmt/format.h>

#include <array>
#include <cstdio>
#include <memory>

#include "pwl/errors.hpp"

namespace pwl::app {

std::string shell_quoted(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string captured_output(const std::string& command) {
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen((command + " 2>&1").c_str(), "r"), pclose);
  if (!pipe) throw Error(fmt::format("cannot run: {}", command));
  std::string out;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe.get()) != nullptr) {
    out += buffer.data();
  }
  const int status = pclose(pipe.release());
  if (status != 0) throw Error(fmt::format("{} failed:\n{}", command, out));
  return out;
}

}  // namespace pwl::app
