#pragma once
// Option tables (`sim.addCar{…}`, `pitwall.mindroad{…}`, `car:lights{…}`): the one way a binding
// reads one. lua::Options checks, when it is made, that the value is a table (or nothing) and
// that every key is one of the options, refusing a typo by name with the nearest option
// (checkOptions, lua_options.cpp); then each option is read by name and kind, a number or a whole
// number range-checked with the engine's one wording ("port 70000 is out of range 1..65535",
// engine/core/numbers.hpp), a name turned into an enum with the names it could have been.
#include <lua.hpp>

#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "bindings/lua_args.hpp"

namespace pitwall::lua {

// An option table (`sim.addCar{…}`, `car:lights{…}`) at stack index idx holds only the keys in
// `known`: else raises "<fn>: unknown option <key>; did you mean <nearest>? (the options are …)".
// A key that is not a string (`{3}`, `{[true] = 1}`) is refused by its type and value; a key too
// long or not printable is shown shortened and escaped. Nothing happens when idx is not a table.
void checkOptions(lua_State* L, int idx, std::string_view fn, std::span<const char* const> known);

// "WHAT 'NAME' is unknown; did you mean X? (use a, b or c)": the one wording for a name that is
// none of `names`.
std::string unknownName(std::string_view what, std::string_view name,
                        std::span<const char* const> names);

// The name at idx among `names` (name, value pairs): its value; anything else is refused with
// unknownName's sentence.
template <class E, std::size_t N>
E checkName(lua_State* L, int idx, const char* what, const std::pair<const char*, E> (&names)[N]) {
  const std::string name = checkString(L, idx, what);
  for (const auto& [n, value] : names)
    if (name == n) return value;
  std::array<const char*, N> list;
  for (std::size_t i = 0; i < N; ++i) list[i] = names[i].first;
  throw LuaError(unknownName(what, name, list));
}

class Options {
 public:
  // The table at idx, or nothing (nil, none: every option unset). Anything else is refused with
  // "FN takes a table {SHAPE}, got TYPE"; an unknown key as checkOptions refuses it.
  Options(lua_State* L, int idx, std::string_view fn, std::span<const char* const> known,
          std::string_view shape);

  bool given() const { return table_; }
  // Pushes the option's value as it is, for a reader of its own (a model by name or number);
  // false, nothing pushed, when it is absent.
  bool value(const char* key);
  // A number with no fixed range (its caller checks it), named `what` in a type error.
  std::optional<double> number(const char* key, const char* what);
  // Each is unset when the option is absent (or nil). `what` names a wrong value's kind in the
  // error ("sensor model must be a string"); by default the key.
  std::optional<std::string> string(const char* key, const char* what = nullptr);
  std::optional<bool> boolean(const char* key);
  // A range error names the key, the value, `unit` and the range's reason `why`.
  std::optional<double> number(const char* key, double lo, double hi, std::string_view unit = {},
                               std::string_view why = {});
  std::optional<long long> integer(const char* key, long long lo, long long hi,
                                   std::string_view unit = {}, std::string_view why = {});

 private:
  lua_State* L_;
  int idx_;
  std::string_view fn_;
  bool table_;
};

}  // namespace pitwall::lua
