#pragma once
// A folder of its own for a test (mkdtemp under $TMPDIR or /tmp), removed with all it holds when
// the test is done.
#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace pitwall::testing {

struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& prefix = "pitwall-test") {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp " + pattern + " failed");
    path = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path / name).string(); }
};

}  // namespace pitwall::testing
