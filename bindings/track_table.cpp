// A track layout as a plain Lua table (track_table.hpp).
#include "bindings/track_table.hpp"

#include "bindings/lua_args.hpp"
#include "engine/protocol/anki/pieces.hpp"
#include "engine/sim/track.hpp"

namespace pitwall {

void pushTrackTable(lua_State* L, const sim::Track& track) {
  lua_createtable(L, 0, 4);
  lua::setString(L, "name", track.name());
  lua::setNumber(L, "lapLength", track.lapLength(0));
  lua::setInteger(L, "finishIndex", static_cast<lua_Integer>(track.finishIndex()) + 1);
  lua_createtable(L, static_cast<int>(track.size()), 0);
  for (std::size_t i = 0; i < track.size(); ++i) {
    const sim::Piece& p = track.piece(i);
    lua_createtable(L, 0, 6);
    lua::setInteger(L, "id", p.id);
    lua::setString(L, "type", anki::pieceTypeName(p.type));
    lua::setInteger(L, "turn", p.turn);
    lua::setNumber(L, "length", p.length(0));
    if (p.turn != 0) {
      lua::setNumber(L, "radius", p.radius());
      lua::setNumber(L, "angle", p.angle());
    }
    lua_rawseti(L, -2, static_cast<lua_Integer>(i) + 1);
  }
  lua_setfield(L, -2, "pieces");
}

}  // namespace pitwall
