#pragma once
// A track layout as Lua sees it (sim.track(), pitwall.layout()): {name, lapLength, finishIndex,
// pieces = {{id, type, turn, length, radius, angle}, …}}, pushed on the stack.
struct lua_State;
namespace pitwall::sim {
class Track;
}
namespace pitwall {
void pushTrackTable(lua_State* L, const sim::Track& track);
}  // namespace pitwall
