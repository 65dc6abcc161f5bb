#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include "engine/core/log.hpp"

int main(int argc, char** argv) {
  pitwall::log::setLevel(pitwall::log::Level::Warn);  // keep "connected" lines out of results
  doctest::Context context(argc, argv);
  return context.run();
}
