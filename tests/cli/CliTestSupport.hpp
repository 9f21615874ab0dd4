#pragma once
// Running the `scalespace` program from a test: its exit code and stderr, in a scratch folder per
// test (the Cli fixture).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace scalespace::test {

namespace fs = std::filesystem;

struct Result {
  int code;         // exit code; -1 when killed by a signal
  std::string err;  // stderr
  std::string out;  // stdout
};

inline std::string readAndRemove(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  in.close();
  fs::remove(file);
  return ss.str();
}

// Runs the CLI with `args`, capturing stdout and stderr.
inline Result run(const std::string& args) {
  static int counter = 0;
  const std::string stem =
      "scalespace_cli_" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
  const fs::path errFile = fs::temp_directory_path() / (stem + ".err");
  const fs::path outFile = fs::temp_directory_path() / (stem + ".out");
  const std::string cmd = std::string(SCALESPACE_CLI_PATH) + " " + args + " >" + outFile.string() +
                          " 2>" + errFile.string();
  const int status = std::system(cmd.c_str());
  Result r{WIFEXITED(status) ? WEXITSTATUS(status) : -1, readAndRemove(errFile), {}};
  r.out = readAndRemove(outFile);
  return r;
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("scalespace_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

}  // namespace scalespace::test
