// Runs one bad-input case file (tests/cases/*.case): the program is run as
// the file says, and its exit code and messages must be the ones the file
// expects. CTest runs every case file through this program, so the next
// hostile input someone finds is one small file to add.
//
// The format, one directive per line ('#' starts a comment line):
//
//   setup:  SHELL COMMAND    run by /bin/sh in the case's fresh temporary
//                            folder before the program (any number)
//   env:    NAME=VALUE       set for the program (any number)
//   args:   ARGUMENTS        depthbench's arguments, split at spaces; quote
//                            with '...' or "..." ('' is an empty argument)
//   exit:   CODE             the exit code expected (required)
//   stderr: TEXT             must appear in standard error (any number)
//   stdout: TEXT             must appear in standard output (any number)
//   no-stdout:               standard output must be empty
//   check:  SHELL COMMAND    must succeed afterwards, run like setup
//
// In every value, @TMP@ is the case's temporary folder, @SOURCE@ the
// source tree and @DEPTHBENCH@ the program (for setup lines that make its
// inputs, e.g. results files to merge).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "tests/command_runner.h"

namespace {

namespace fs = std::filesystem;

struct Case {
  std::vector<std::string> setup, env, checks, stderr_has, stdout_has;
  std::vector<std::string> args;
  int exit_code = -1;
  bool no_stdout = false;
};

std::string Substitute(std::string text, const std::string& tmp) {
  const std::pair<std::string, std::string> names[] = {
      {"@TMP@", tmp}, {"@SOURCE@", DEPTHBENCH_SOURCE_DIR}, {"@DEPTHBENCH@", DEPTHBENCH_BINARY_DIR "/bench/depthbench"}};
  for (const auto& [name, value] : names) {
    for (auto at = text.find(name); at != std::string::npos; at = text.find(name, at + value.size())) {
      text.replace(at, name.size(), value);
    }
  }
  return text;
}

// Splits at spaces; '...' and "..." group (and may be empty).
bool SplitArguments(const std::string& line, std::vector<std::string>& out) {
  std::string word;
  bool in_word = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '\'' || c == '"') {
      const auto end = line.find(c, i + 1);
      if (end == std::string::npos) return false;
      word += line.substr(i + 1, end - i - 1);
      in_word = true;
      i = end;
    } else if (c == ' ' || c == '\t') {
      if (in_word) out.push_back(word);
      word.clear();
      in_word = false;
    } else {
      word += c;
      in_word = true;
    }
  }
  if (in_word) out.push_back(word);
  return true;
}

bool Parse(const fs::path& file, const std::string& tmp, Case& c, std::string& error) {
  std::ifstream in(file);
  if (!in) return error = "cannot read " + file.string(), false;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) return error = "line " + std::to_string(number) + ": no 'directive:'", false;
    const std::string key = line.substr(0, colon);
    std::string value = line.substr(colon + 1);
    value.erase(0, value.find_first_not_of(" \t") == std::string::npos ? value.size() : value.find_first_not_of(" \t"));
    value = Substitute(value, tmp);
    if (key == "setup") {
      c.setup.push_back(value);
    } else if (key == "env") {
      c.env.push_back(value);
    } else if (key == "args") {
      if (!SplitArguments(value, c.args)) return error = "line " + std::to_string(number) + ": unclosed quote", false;
    } else if (key == "exit") {
      c.exit_code = std::atoi(value.c_str());
    } else if (key == "stderr") {
      c.stderr_has.push_back(value);
    } else if (key == "stdout") {
      c.stdout_has.push_back(value);
    } else if (key == "no-stdout") {
      c.no_stdout = true;
    } else if (key == "check") {
      c.checks.push_back(value);
    } else {
      return error = "line " + std::to_string(number) + ": unknown directive '" + key + "'", false;
    }
  }
  if (c.exit_code < 0) return error = "no 'exit:' line", false;
  if (c.args.empty()) return error = "no 'args:' line", false;
  return true;
}

bool Shell(const std::string& tmp, const std::string& command) {
  // `cd` on a line of its own: after `cd DIR && COMMAND`, a `&` inside
  // COMMAND would put the cd in the background job too, and the rest of
  // the line would run in the test's own folder.
  const std::string line = "cd '" + tmp + "' || exit 1\n" + command;
  return std::system(line.c_str()) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: bad_input_cases FILE.case\n";
    return 2;
  }
  const fs::path file = argv[1];
  const std::string tmp = depthbench::testing::MakeTempDir("case_" + file.stem().string());
  Case c;
  std::string error;
  if (!Parse(file, tmp, c, error)) {
    std::cerr << file.string() << ": " << error << "\n";
    return 2;
  }
  int failures = 0;
  auto fail = [&](const std::string& what) {
    std::cerr << "FAILED: " << what << "\n";
    ++failures;
  };
  for (const auto& command : c.setup) {
    if (!Shell(tmp, command)) fail("setup '" + command + "'");
  }
  for (const auto& assignment : c.env) {
    const auto eq = assignment.find('=');
    ::setenv(assignment.substr(0, eq).c_str(), eq == std::string::npos ? "" : assignment.substr(eq + 1).c_str(), 1);
  }
  const auto result = depthbench::testing::RunDepthbench(c.args);
  if (result.exit_code != c.exit_code) {
    fail("exit code " + std::to_string(result.exit_code) + ", expected " + std::to_string(c.exit_code));
  }
  for (const auto& text : c.stderr_has) {
    if (result.err.find(text) == std::string::npos) fail("stderr lacks '" + text + "'");
  }
  for (const auto& text : c.stdout_has) {
    if (result.out.find(text) == std::string::npos) fail("stdout lacks '" + text + "'");
  }
  if (c.no_stdout && !result.out.empty()) fail("stdout is not empty");
  for (const auto& command : c.checks) {
    if (!Shell(tmp, command)) fail("check '" + command + "'");
  }
  if (failures > 0) {
    std::cerr << "--- stdout:\n" << result.out << "--- stderr:\n" << result.err;
  }
  fs::remove_all(tmp);
  return failures == 0 ? 0 : 1;
}
