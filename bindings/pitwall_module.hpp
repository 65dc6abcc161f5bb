#pragma once
// The `pitwall` global: cars, clock, timers, tasks, stop, log; and `pitwall.sim` when the
// simulator is the transport (sim_binding.cpp).
namespace pitwall {
class ScriptHost;
}  // namespace pitwall
struct lua_State;
namespace pitwall {
void openPitwallModule(ScriptHost& host);
void openSimModule(ScriptHost& host);  // leaves nothing on the stack; sets pitwall.sim
// sim.script and sim.reload (script_under_test.cpp) on the pitwall.sim table on top of the stack.
void openScriptUnderTest(lua_State* L);
// pitwall.mindroad{…} and pitwall.alphabot{…}: the seed robots (docs/robots.md). Each leaves
// nothing on the stack and sets its function in the `pitwall` table.
void openMindroadModule(ScriptHost& host);
void openAlphabotModule(ScriptHost& host);
// pitwall.view (view_binding.cpp): what a script tells the race view.
void openViewModule(ScriptHost& host);
// pitwall.seats, pitwall.seat and sim.openSeats (seat_binding.cpp): human drivers' seats.
void openSeatModule(ScriptHost& host);
// pitwall.driverFiles and pitwall._driverWorld (driver_world_binding.cpp): driver files, each in
// a Lua world of its own (docs/drivers.md).
void openDriverWorlds(ScriptHost& host);
// pitwall.classroom (classroom_binding.cpp): the view's code page's classroom (--code).
void openClassroomModule(ScriptHost& host);
}  // namespace pitwall
