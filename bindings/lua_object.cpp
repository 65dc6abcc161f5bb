#include "bindings/lua_object.hpp"

namespace pitwall::lua {

bool beginEvent(const EventSource& source, std::size_t e, int tableRef) {
  const EventSlots& slots = source.slots;
  if (!slots.wanted(e)) return false;
  lua_State* L = source.host.state();
  const int hub = slots.hub(e);
  lua_pushcfunction(L, traceback);
  lua_rawgeti(L, LUA_REGISTRYINDEX, hub != LUA_NOREF ? hub : slots.handler(e));
  lua_rawgeti(L, LUA_REGISTRYINDEX, source.selfRef);
  if (tableRef != LUA_NOREF)
    lua_rawgeti(L, LUA_REGISTRYINDEX, tableRef);
  else
    lua_createtable(L, 0, 4);
  lua_pushnumber(L, source.host.loop().seconds());
  lua_setfield(L, -2, "time");
  return true;
}

void finishEvent(const EventSource& source, std::size_t e, int tableRef) {
  const EventSlots& slots = source.slots;
  ScriptHost& host = source.host;
  lua_State* L = host.state();
  const bool hubFirst = slots.hub(e) != LUA_NOREF;
  const bool both = hubFirst && slots.handler(e) != LUA_NOREF;
  if (both && tableRef == LUA_NOREF) {  // the handler gets the same fresh table: keep a copy
    lua_pushvalue(L, -1);
    lua_insert(L, -5);
  }
  host.callAboveHandler(2, hubFirst ? source.names.listenersWhat(e) : source.names.handlerWhat(e),
                        source.who);
  if (!both) return;
  // The listeners ran: now the object's own handler, with the same table (read after the
  // listeners, which may have changed it). Its slot is read again: a listener may have removed it.
  if (slots.handler(e) == LUA_NOREF) {
    if (tableRef == LUA_NOREF) lua_pop(L, 1);
    return;
  }
  lua_pushcfunction(L, traceback);
  lua_rawgeti(L, LUA_REGISTRYINDEX, slots.handler(e));
  lua_rawgeti(L, LUA_REGISTRYINDEX, source.selfRef);
  if (tableRef != LUA_NOREF)
    lua_rawgeti(L, LUA_REGISTRYINDEX, tableRef);
  else
    lua_rotate(L, -4, -1);  // the kept copy, from under the three, to the top
  host.callAboveHandler(2, source.names.handlerWhat(e), source.who);
}

bool pushCallee(const EventSource& source, std::size_t e, bool hub) {
  const int ref = hub ? source.slots.hub(e) : source.slots.handler(e);
  if (ref == LUA_NOREF) return false;
  lua_State* L = source.host.state();
  lua_pushcfunction(L, traceback);
  lua_rawgeti(L, LUA_REGISTRYINDEX, ref);
  lua_rawgeti(L, LUA_REGISTRYINDEX, source.selfRef);
  return true;
}

void callCallee(const EventSource& source, std::size_t e, bool hub, int nargs) {
  source.host.callAboveHandler(
      1 + nargs, hub ? source.names.listenersWhat(e) : source.names.handlerWhat(e), source.who);
}

int setHub(lua_State* L) {
  const ObjectType* type = nullptr;
  if (luaL_getmetafield(L, 1, "__objecttype") != LUA_TNIL) {
    type = static_cast<const ObjectType*>(lua_touserdata(L, -1));
    lua_pop(L, 1);
  }
  if (!type || !type->slotsOf)
    throw LuaError("expected a car or a robot (an object with events), got " + typeName(L, 1));
  setHubOf(L, *type, type->slotsOf(L, 1), type->unlistened);
  return 0;
}

}  // namespace pitwall::lua
