#pragma once
// Plain data from one Lua world into another (bindings/world_copy.cpp): a hot reload's
// pitwall.persist and carried state (bindings/reloader.cpp), what the race director tells a
// driver world (bindings/driver_world.cpp). Numbers, strings, booleans and tables (sharing and
// cycles kept: tables already copied are found again through a memo); a car stays the same car
// (its object in the other world); a list of cars stays one; functions, other userdata, threads
// and metatables stay behind — named in `dropped`, unless quiet.
#include <lua.hpp>

#include <string>
#include <vector>

namespace pitwall::lua {

class WorldCopy {
 public:
  // quiet: what cannot cross is left out without being named (the library's own state, whose
  // functions and metatables stay behind by design: the new version brings its own).
  WorldCopy(lua_State* from, lua_State* to, std::vector<std::string>& dropped, bool quiet = false)
      : from_(from), to_(to), dropped_(dropped), quiet_(quiet) {}

  // Copies the value at `from` index idx onto `to`'s stack; false (nothing pushed) when it
  // cannot be copied. `path` names it in `dropped` ("pitwall.persist").
  bool copy(int idx, const std::string& path, int depth);

  // The memo lives on `to`'s stack between these two (copy needs it).
  void openMemo() {
    lua_newtable(to_);
    memo_ = lua_gettop(to_);
  }
  void closeMemo() { lua_remove(to_, memo_); }

 private:
  bool table(int idx, const std::string& path, int depth);
  // How a key reads in a path: ".name", "[3]", "[boolean]".
  std::string keyText(int idx);

  lua_State* from_;
  lua_State* to_;
  std::vector<std::string>& dropped_;
  bool quiet_;
  int memo_ = 0;
};

}  // namespace pitwall::lua
