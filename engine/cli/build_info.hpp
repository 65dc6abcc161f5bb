#pragma once
// What the build knew (generated from packaging/build_info.cpp.in at every build): the project's
// version (CMakeLists.txt), `git describe` of the source when it was a git checkout (else ""),
// and the sdbus-c++ the binary was built against.
namespace pitwall::cli::build {
extern const char* const version;
extern const char* const gitDescribe;
extern const char* const sdbusVersion;
}  // namespace pitwall::cli::build
