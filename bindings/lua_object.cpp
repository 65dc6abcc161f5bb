#include "bindings/lua_object.hpp"

#include <cctype>
#include <stdexcept>
#include <string>
#include <string_view>

namespace pitwall::lua {

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

namespace {

// The TypeSpec of the object at idx (its metatable's __objecttype), or nullptr.
const TypeSpec* specOf(lua_State* L, int idx) {
  // Only a userdata's: a script sets a table's metatable, and could give it any __objecttype.
  if (lua_type(L, idx) != LUA_TUSERDATA) return nullptr;
  const int kind = luaL_getmetafield(L, idx, "__objecttype");
  if (kind == LUA_TNIL) return nullptr;
  const auto* type =
      kind == LUA_TLIGHTUSERDATA ? static_cast<const TypeSpec*>(lua_touserdata(L, -1)) : nullptr;
  lua_pop(L, 1);
  return type;
}

std::string labelOf(lua_State* L, int self, const TypeSpec& type) {
  return type.label ? type.label(L, self) : std::string(type.name);
}

bool startsLikeEvent(const std::string& key) {
  return key.size() > 2 && key[0] == 'o' && key[1] == 'n' &&
         std::isupper(static_cast<unsigned char>(key[2]));
}

// "a script under test has no field 'x' (started, finished, …)": key 2 of the object at 1.
std::string noSuchField(lua_State* L, const TypeSpec& type) {
  std::string names;
  for (const Field& f : type.fields) names += (names.empty() ? "" : ", ") + std::string(f.name);
  for (const luaL_Reg* m = type.methods; m && m->name; ++m)
    names += (names.empty() ? ":" : ", :") + std::string(m->name);
  return std::string("a ") + whatOf(type) + " has no field '" + luaL_tolstring(L, 2, nullptr) +
         "' (" + names + ")";
}

// __index (1: the object, 2: the key). Upvalues: 1 the fields' numbers by name, 2 the methods
// table (a binding may replace a method in it after registerType: alphabot's ping), 3 the
// TypeSpec, 4 the metatable. A state field (the hot path: one lookup), else a method (no field
// has a method's name: registerType), else (ownFields) the object's own table, else nil.
int index(lua_State* L) {
  lua_pushvalue(L, 2);
  if (lua_rawget(L, lua_upvalueindex(1)) != LUA_TNUMBER) {
    lua_pop(L, 1);
    lua_pushvalue(L, 2);
    if (lua_rawget(L, lua_upvalueindex(2)) != LUA_TNIL) return 1;
    lua_pop(L, 1);
    lua_pushnil(L);  // (no field: the check below, then the object's own table)
  }
  const auto& type = *static_cast<const TypeSpec*>(lua_touserdata(L, lua_upvalueindex(3)));
  // The object is of this type — its metatable is the one this __index belongs to (an upvalue:
  // the hot path of every car field read, no registry lookup) — else checkBox's sentence.
  const bool own = lua_type(L, 1) == LUA_TUSERDATA && lua_getmetatable(L, 1);
  if (!own || !lua_rawequal(L, -1, lua_upvalueindex(4))) checkBox(L, 1, type);
  if (own) lua_pop(L, 1);
  if (lua_type(L, -1) == LUA_TNUMBER) {
    const auto i = static_cast<std::size_t>(lua_tointeger(L, -1));
    lua_pop(L, 1);
    type.fields[i].push(L, 1);
    return 1;
  }
  lua_pop(L, 1);
  if (!type.ownFields) {
    if (type.strict) throw LuaError(noSuchField(L, type));
    lua_pushnil(L);
    return 1;
  }
  lua_getiuservalue(L, 1, 1);
  lua_pushvalue(L, 2);
  lua_rawget(L, -2);
  return 1;
}

// __newindex's checks (1: the object, 2: the key, 3: the value): an event's handler is checked
// (a function or nil) and taken into the object's slots (true: done); a state field, a method, or
// an onX that is no event (a typo would never be called) is refused by name; without ownFields
// anything else is refused. False: the value is the script's own field.
bool assignChecked(lua_State* L, const TypeSpec& type) {
  checkBox(L, 1, type);
  const std::string what = whatOf(type);
  if (lua_type(L, 2) == LUA_TSTRING) {
    const std::string key = lua_tostring(L, 2);
    if (const int e = type.events ? type.events->find(key) : -1; e >= 0) {
      if (!lua_isnil(L, 3) && !lua_isfunction(L, 3))
        throw LuaError(what + "." + key + " must be a function or nil, got " + typeName(L, 3));
      if (lua_isfunction(L, 3) && type.closed && type.closed(L, 1))
        throw LuaError(labelOf(L, 1, type) + " is closed: it has no more events");
      type.slotsOf(L, 1).setHandler(L, static_cast<std::size_t>(e), 3);
      return !type.ownFields;  // kept in its own table too, so reading it gives it back
    }
    if (startsLikeEvent(key))
      throw LuaError(what + "." + key + " is not an event; " +
                     (type.events ? "the events are " + joinNames(type.events->names())
                                  : "a " + what + " has no events"));
    for (const Field& f : type.fields)
      if (key == f.name)
        throw LuaError(what + "." + key + " is read-only (it is the " + what + "'s state)");
    lua_pushvalue(L, 2);
    const bool isMethod = lua_rawget(L, lua_upvalueindex(1)) != LUA_TNIL;
    lua_pop(L, 1);
    if (isMethod) throw LuaError(what + ":" + key + " is a method and cannot be replaced");
  }
  if (!type.ownFields)
    throw LuaError("cannot set " + std::string(luaL_tolstring(L, 2, nullptr)) + " on a " + what +
                   ": it keeps no fields of a script's own (keep them in a table of yours)");
  return false;
}

// __newindex (1: the object, 2: the key, 3: the value). Upvalues: 1 the methods table, 2 the
// TypeSpec. The checks run first, their strings gone before Lua may raise an error of its own
// (a nil or NaN key) here: a longjmp must not cross a live C++ object.
int newindex(lua_State* L) {
  const auto& type = *static_cast<const TypeSpec*>(lua_touserdata(L, lua_upvalueindex(2)));
  if (assignChecked(L, type)) return 0;
  lua_settop(L, 3);
  lua_getiuservalue(L, 1, 1);
  lua_pushvalue(L, 2);
  lua_pushvalue(L, 3);
  lua_rawset(L, 4);
  return 0;
}

int tostring(lua_State* L) {
  const auto& type = *static_cast<const TypeSpec*>(lua_touserdata(L, lua_upvalueindex(1)));
  checkBox(L, 1, type);
  const std::string s = labelOf(L, 1, type);
  lua_pushlstring(L, s.data(), s.size());
  return 1;
}

int gc(lua_State* L) {
  const auto& type = *static_cast<const TypeSpec*>(lua_touserdata(L, lua_upvalueindex(1)));
  if (!testBox(L, 1, type)) return 0;
  type.gc(L, 1);
  // What the box held is gone, but the object may be met again: a weak-keyed table keeps a
  // finalized key until the next collection. Without its type it is a plain userdata there, which
  // every check refuses ("expected a mindroad robot, got userdata").
  lua_pushnil(L);
  lua_setmetatable(L, 1);
  return 0;
}

void pushNames(lua_State* L, std::size_t n, const char* (*nameAt)(const TypeSpec&, std::size_t),
               const TypeSpec& type) {
  lua_createtable(L, static_cast<int>(n), 0);
  for (std::size_t i = 0; i < n; ++i) {
    lua_pushstring(L, nameAt(type, i));
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
}

}  // namespace

std::string expectedSentence(lua_State* L, int idx, const TypeSpec& type) {
  // "a car", "an alphabot", "a mindroad robot" (its name, and what it is when that differs)
  const std::string what = type.what && std::string_view(type.what) != type.name
                               ? std::string(type.name) + " " + type.what
                               : std::string(type.name);
  const bool vowel =
      std::string_view("aeiou").find(what.empty() ? 'x' : what[0]) != std::string_view::npos;
  std::string got = typeName(L, idx);
  if (lua_type(L, idx) == LUA_TUSERDATA) {
    if (const TypeSpec* other = specOf(L, idx)) got = whatOf(*other);
  }
  return std::string("expected ") + (vowel ? "an " : "a ") + what + ", got " + got;
}

void* allocateBox(lua_State* L, const TypeSpec& type, std::size_t size) {
  return lua_newuserdatauv(L, size, type.ownFields ? 1 : 0);
}

void finishBox(lua_State* L, const TypeSpec& type) {
  luaL_setmetatable(L, type.metatable);
  if (type.ownFields) {
    lua_newtable(L);
    lua_setiuservalue(L, -2, 1);
  }
}

void registerType(lua_State* L, const TypeSpec& type) {
  if (!luaL_newmetatable(L, type.metatable)) {
    lua_pop(L, 1);
    return;
  }
  const int mt = lua_gettop(L);
  auto* spec = const_cast<TypeSpec*>(&type);
  lua_pushvalue(L, mt);  // (testBox finds it by the type's address)
  lua_rawsetp(L, LUA_REGISTRYINDEX, &type);
  lua_newtable(L);  // the methods
  if (type.methods) luaL_setfuncs(L, type.methods, 0);
  const int methods = lua_gettop(L);
  lua_pushvalue(L, methods);
  lua_setfield(L, mt, "__methods");
  // __fields and __events, which the REPL completes from and the types generator reads
  pushNames(
      L, type.fields.size(), [](const TypeSpec& t, std::size_t i) { return t.fields[i].name; },
      type);
  lua_setfield(L, mt, "__fields");
  pushNames(
      L, type.events ? type.events->size() : 0,
      [](const TypeSpec& t, std::size_t i) { return t.events->name(i); }, type);
  lua_setfield(L, mt, "__events");
  lua_createtable(L, 0, static_cast<int>(type.fields.size()));  // field numbers by name
  for (std::size_t i = 0; i < type.fields.size(); ++i) {
    for (const luaL_Reg* m = type.methods; m && m->name; ++m)
      if (std::string_view(m->name) == type.fields[i].name)
        throw std::logic_error(std::string(type.name) + " has a field and a method named " +
                               m->name);
    lua_pushinteger(L, static_cast<lua_Integer>(i));
    lua_setfield(L, -2, type.fields[i].name);
  }
  lua_pushvalue(L, methods);
  lua_pushlightuserdata(L, spec);
  lua_pushvalue(L, mt);  // (index's check of its object: this metatable, no registry lookup)
  lua_pushcclosure(L, guarded<index>, 4);
  lua_setfield(L, mt, "__index");
  lua_pushvalue(L, methods);
  lua_pushlightuserdata(L, spec);
  lua_pushcclosure(L, guarded<newindex>, 2);
  lua_setfield(L, mt, "__newindex");
  lua_pushlightuserdata(L, spec);
  lua_pushcclosure(L, guarded<tostring>, 1);
  lua_setfield(L, mt, "__tostring");
  if (type.gc) {
    lua_pushlightuserdata(L, spec);
    lua_pushcclosure(L, gc, 1);
    lua_setfield(L, mt, "__gc");
  }
  lua_pushstring(L, type.name);
  lua_setfield(L, mt, "__name");
  lua_pushlightuserdata(L, spec);  // the type itself, for what works on every type (setHub)
  lua_setfield(L, mt, "__objecttype");
  lua_settop(L, mt);
  lockMetatable(L, mt);
  lua_pop(L, 1);
}

void setTableType(lua_State* L, int idx, const char* metatable, const char* name,
                  lua_CFunction index) {
  idx = lua_absindex(L, idx);
  if (luaL_newmetatable(L, metatable)) {
    lua_pushcfunction(L, index);
    lua_setfield(L, -2, "__index");
    lua_pushstring(L, name);
    lua_setfield(L, -2, "__name");
    lockMetatable(L, -1);
  }
  lua_setmetatable(L, idx);
}

bool hasTableType(lua_State* L, int idx, const char* metatable) {
  if (!lua_getmetatable(L, idx)) return false;
  luaL_getmetatable(L, metatable);
  const bool is = lua_rawequal(L, -1, -2);
  lua_pop(L, 2);
  return is;
}

int setHub(lua_State* L) {
  const TypeSpec* type = specOf(L, 1);
  if (!type || !type->events || !type->slotsOf)
    throw LuaError("expected a car or a robot (an object with events), got " +
                   (type ? std::string(whatOf(*type)) : typeName(L, 1)));
  const EventNames& events = *type->events;
  const std::string name = checkString(L, 2, "event name");
  const int e = events.find(name);
  const char* except = type->unlistened;
  if (e < 0 || (except && name == except))
    throw LuaError(
        "cannot listen to '" + name + "'; the events are " + joinNames(events.names()) +
        (except ? std::string(" (") + except + " only through " + type->name + "." + except + ")"
                : std::string()));
  if (!lua_isnil(L, 3) && !lua_isfunction(L, 3))
    throw LuaError(std::string("a listener hub must be a function or nil, got ") +
                   luaL_typename(L, 3));
  if (lua_isfunction(L, 3) && type->closed && type->closed(L, 1))
    throw LuaError(labelOf(L, 1, *type) + " is closed: it has no more events");
  type->slotsOf(L, 1).setHub(L, static_cast<std::size_t>(e), 3);
  return 0;
}

}  // namespace pitwall::lua
