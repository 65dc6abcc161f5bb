// pitwall.view: what a script tells the race view (docs/view.md "race"). The race library
// reports its sessions and the map a scan learnt; a script may add lines to the event log.
//   pitwall.view.active          true when the run serves a view (--view)
//   pitwall.view.recording       true when the run keeps a record (--record): the race's
//                                state goes into it too, for a replay's view
//   pitwall.view.race(t | nil)   the race's state: a table of plain data (no functions)
//   pitwall.view.track(map)      a map of pitwall.track: its pieces are drawn (real cars)
//   pitwall.view.event(text [, level])
// Without a view (or a record) they do nothing, so a script never needs to ask.
#include <cmath>

#include "bindings/copy_budget.hpp"
#include "bindings/lua_args.hpp"
#include "bindings/lua_json.hpp"
#include "bindings/lua_options.hpp"
#include "bindings/pitwall_module.hpp"
#include "bindings/script_host.hpp"
#include "engine/core/printable.hpp"
#include "engine/view/feed.hpp"

namespace pitwall {

using lua::LuaError;

namespace {

constexpr int kMaxDepth = 16;
constexpr std::size_t kMaxEntries = 100000;  // values in one race table, all levels
// The bytes of one race table's copy (its strings and keys, and kValueBytes a value): a race's
// summary is a few KB; the copy is made in C++, where neither the budget nor Ctrl-C can stop it,
// so it is bounded to what takes well under 100 ms, and charged to the world's memory cap.
constexpr std::size_t kMaxBytes = std::size_t{8} << 20;
constexpr std::size_t kValueBytes = 64;  // what a JSON value costs besides its text

view::Feed* feedOf(lua_State* L) {
  return ScriptHost::from(L).options().view;
}

int race(lua_State* L) {
  view::Feed* feed = feedOf(L);
  ScriptHost& host = ScriptHost::from(L);
  const auto& record = host.options().recordRace;
  if (!feed && !record) return 0;
  if (lua_isnoneornil(L, 1)) {
    if (feed) feed->setRace(nullptr);
    if (record) record(nullptr);
    host.chargeOutside(0);
    return 0;
  }
  luaL_checktype(L, 1, LUA_TTABLE);
  lua::CopyBudget budget(L, "pitwall.view.race", kMaxBytes, host.memory().outside);
  nlohmann::json race = lua::toJson(
      L, 1, {"pitwall.view.race", "the view", kMaxDepth, kMaxEntries, kValueBytes}, budget, "race");
  if (record) record(race);
  if (feed) feed->setRace(std::move(race));
  host.chargeOutside(budget.bytes());  // the feed keeps it until the next race table
  return 0;
}

// A map of pitwall.track ({pieces = {{id, turn = "left"|"right"|nil}, …}}) as a track to draw,
// starting with the start piece (34) as layouts do. A simulator's layout is the truth and stays.
int track(lua_State* L) {
  view::Feed* feed = feedOf(L);
  if (!feed) return 0;
  luaL_checktype(L, 1, LUA_TTABLE);
  if (feed->trackSourceIsLayout()) return 0;
  // Raw reads only: no metamethod of the script's runs here (a Lua error would jump over the
  // C++ objects below).
  lua_pushliteral(L, "pieces");
  lua_rawget(L, 1);
  if (!lua_istable(L, -1)) throw LuaError("pitwall.view.track: the map has no pieces list");
  std::vector<sim::Piece> pieces;
  const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L, -1));
  if (n > 10000) throw LuaError("pitwall.view.track: a map of " + std::to_string(n) + " pieces?");
  for (lua_Integer i = 1; i <= n; ++i) {
    lua_rawgeti(L, -1, i);
    if (!lua_istable(L, -1))
      throw LuaError("pitwall.view.track: piece " + std::to_string(i) + " is not a table");
    lua_pushliteral(L, "id");
    lua_rawget(L, -2);
    int isInteger = 0;
    lua_Integer id = lua_tointegerx(L, -1, &isInteger);
    lua_pushliteral(L, "turn");
    lua_rawget(L, -3);
    std::string turn = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "";
    lua_pop(L, 3);
    if (!isInteger || id < 0 || id > 255)
      throw LuaError("pitwall.view.track: piece " + std::to_string(i) +
                     " needs an id, a road piece number 0–255" +
                     (isInteger ? ", not " + std::to_string(id) : ""));
    sim::Piece p;
    p.id = static_cast<std::uint8_t>(id);
    p.type = anki::pieceType(p.id);
    p.turn = p.type == anki::PieceType::Curve ? (turn == "left" ? 1 : turn == "right" ? -1 : 0) : 0;
    pieces.push_back(p);
  }
  lua_pop(L, 1);
  auto start = std::find_if(pieces.begin(), pieces.end(),
                            [](const sim::Piece& p) { return p.id == anki::kFinishBefore; });
  if (start != pieces.end()) std::rotate(pieces.begin(), start, pieces.end());
  feed->setTrack(sim::Track("scanned", std::move(pieces)), "scan");
  return 0;
}

constexpr std::pair<const char*, const char*> kLevels[] = {
    {"info", "info"}, {"warn", "warn"}, {"error", "error"}};

int event(lua_State* L) {
  std::string text = lua::checkString(L, 1, "the event's text");
  const char* level = lua_isnoneornil(L, 2) ? "info" : lua::checkName(L, 2, "level", kLevels);
  if (view::Feed* feed = feedOf(L)) feed->event(level, text.substr(0, 1000));
  return 0;
}

}  // namespace

void openViewModule(ScriptHost& host) {
  lua_State* L = host.state();
  lua_getglobal(L, "pitwall");
  static const luaL_Reg functions[] = {{"race", lua::guarded<race>},
                                       {"track", lua::guarded<track>},
                                       {"event", lua::guarded<event>},
                                       {nullptr, nullptr}};
  luaL_newlib(L, functions);
  lua_pushboolean(L, host.options().view != nullptr);
  lua_setfield(L, -2, "active");
  lua_pushboolean(L, static_cast<bool>(host.options().recordRace));
  lua_setfield(L, -2, "recording");
  lua_setfield(L, -2, "view");
  lua_pop(L, 1);
}

}  // namespace pitwall
