#pragma once
// What a harness asserts. A failed check prints what was expected and aborts, which libFuzzer
// reports as a crash with the input that caused it (docs/testing.md "Fuzzing and sanitizers").
// Exceptions are not caught here: one escaping LLVMFuzzerTestOneInput is a crash too, because no
// codec or parser under test documents throwing.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>

#include "engine/core/hex.hpp"

#define FUZZ_CHECK(condition, ...)                                                       \
  do {                                                                                   \
    if (!(condition)) {                                                                  \
      std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #condition); \
      ::pitwall::fuzz::explain(__VA_ARGS__);                                             \
      std::abort();                                                                      \
    }                                                                                    \
  } while (0)

namespace pitwall::fuzz {

inline void explain() {}
inline void explain(const std::string& what) {
  std::fprintf(stderr, "  %s\n", what.c_str());
}

// "label: 06 24 e8 …" for a check's explanation.
inline std::string bytesText(const char* label, std::span<const std::uint8_t> bytes) {
  return std::string(label) + ": " + (bytes.empty() ? std::string("(none)") : toHex(bytes));
}

// Splits a fuzz input into parts at the first `separator` byte: lets one input carry two fields
// (a topic and a payload) while each field may hold any other byte.
struct TwoParts {
  std::string first, second;
};
inline TwoParts splitAt(std::span<const std::uint8_t> data, std::uint8_t separator) {
  TwoParts out;
  std::size_t i = 0;
  for (; i < data.size() && data[i] != separator; ++i)
    out.first.push_back(static_cast<char>(data[i]));
  if (i < data.size())
    out.second.assign(data.begin() + static_cast<std::ptrdiff_t>(i + 1), data.end());
  return out;
}

}  // namespace pitwall::fuzz
