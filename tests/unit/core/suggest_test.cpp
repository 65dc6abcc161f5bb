#include "engine/core/suggest.hpp"

#include <doctest/doctest.h>

#include <string>
#include <vector>

using namespace pitwall;

TEST_CASE("editDistance counts insertions, deletions, substitutions and swaps") {
  CHECK(editDistance("run", "run") == 0);
  CHECK(editDistance("rn", "run") == 1);
  CHECK(editDistance("crusier", "cruiser") == 1);  // one swap, not two substitutions
  CHECK(editDistance("spede", "speed") == 1);
  CHECK(editDistance("lapz", "laps") == 1);
  CHECK(editDistance("SetSpeed", "setSpeed") == 0);
  CHECK(editDistance("", "abc") == 3);
  CHECK(editDistance("kitten", "sitting") == 3);
}

TEST_CASE("nearest suggests only a name near enough to have been meant") {
  const std::vector<std::string> commands{"run", "repl", "replay", "bridge", "test", "track"};
  CHECK(nearest("rn", commands) == "run");
  CHECK(nearest("tset", commands) == "test");
  CHECK(nearest("replya", commands) == "replay");
  CHECK(nearest("bri", commands) == "bridge");  // a prefix
  CHECK_FALSE(nearest("x", commands));
  CHECK_FALSE(nearest("frobnicate", commands));
  CHECK_FALSE(nearest("", commands));
  CHECK_FALSE(nearest("run", commands));     // the word itself is no suggestion
  CHECK(nearest("RUN", commands) == "run");  // in another case it is the nearest
  CHECK(nearest("--FAST", std::vector<std::string>{"--fast-cap", "--fast"}) == "--fast");

  const std::vector<std::string> methods{"setSpeed", "setLane", "changeLane", "lights"};
  CHECK(didYouMean("setSped", methods) == "; did you mean setSpeed?");
  CHECK(didYouMean("zzzzzzz", methods).empty());
}
