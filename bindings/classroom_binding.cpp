// pitwall.classroom: the classroom of the view's code page (--code FOLDER, docs/classroom.md), as
// the race script sees it. Always there in a run's world (not in a driver world), as pitwall.view
// is: without --code it is not active, nextStart() is nil and desks() empty.
//   pitwall.classroom.active       true with --code
//   pitwall.classroom.folder       the desks' folder (absolute); nil without --code
//   pitwall.classroom.nextStart()  the race the teacher started on their page, taken once: its
//                                  laps, or nil when none is waiting
//   pitwall.classroom.desks()      {{car, student, joined, saves}, …} in car order
// Each desk's driver file is pitwall.driverFiles[car]: the race library races it in a driver
// world of its own, which a student's save reloads (engine/classroom/classroom.hpp).
#include <map>
#include <optional>

#include "bindings/lua_args.hpp"
#include "bindings/pitwall_module.hpp"
#include "bindings/script_host.hpp"
#include "engine/classroom/classroom.hpp"

namespace pitwall {

namespace {

classroom::Classroom* roomOf(lua_State* L) {
  return ScriptHost::from(L).options().classroom;
}

int nextStart(lua_State* L) {
  auto* room = roomOf(L);
  auto laps = room ? room->takeStart() : std::nullopt;
  laps ? lua_pushinteger(L, *laps) : lua_pushnil(L);
  return 1;
}

int desks(lua_State* L) {
  static const std::map<int, classroom::Desk> none;
  auto* room = roomOf(L);
  const auto& all = room ? room->desks() : none;
  lua_createtable(L, static_cast<int>(all.size()), 0);
  lua_Integer i = 0;
  for (const auto& [car, d] : all) {
    lua_createtable(L, 0, 4);
    lua_pushinteger(L, car);
    lua_setfield(L, -2, "car");
    lua_pushlstring(L, d.student.data(), d.student.size());
    lua_setfield(L, -2, "student");
    lua_pushboolean(L, !d.token.empty());
    lua_setfield(L, -2, "joined");
    lua_pushinteger(L, d.saves);
    lua_setfield(L, -2, "saves");
    lua_rawseti(L, -2, ++i);
  }
  return 1;
}

}  // namespace

void openClassroomModule(ScriptHost& host) {
  auto* room = host.options().classroom;
  lua_State* L = host.state();
  lua_getglobal(L, "pitwall");
  lua_createtable(L, 0, 4);
  lua_pushboolean(L, room != nullptr);
  lua_setfield(L, -2, "active");
  if (room) {
    const std::string folder = room->folder().string();
    lua_pushlstring(L, folder.data(), folder.size());
    lua_setfield(L, -2, "folder");
  }
  lua_pushcfunction(L, lua::guarded<nextStart>);
  lua_setfield(L, -2, "nextStart");
  lua_pushcfunction(L, lua::guarded<desks>);
  lua_setfield(L, -2, "desks");
  lua_setfield(L, -2, "classroom");
  lua_pop(L, 1);
}

}  // namespace pitwall
