#pragma once
// Running another program through the shell: quoting, and reading what it prints.
#include <string>

namespace pwl::app {

// `text` as one shell word ('it'\''s').
std::string shell_quoted(const std::string& text);

// Runs `command` with stderr joined to stdout and returns what it printed; throws pwl::Error
// naming the command and its output when it exits with a non-zero status.
std::string captured_output(const std::string& command);

}  // namespace pwl::app
