#pragma once
// The toggle bit field by name (alphabot.md §3): the one list both the Lua `robot:set{…}` and
// the JSON of `pitwall decode alphabot` use, so a name means the same bit everywhere.
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "engine/protocol/alphabot/messages.hpp"

namespace pitwall::alphabot {

struct ToggleBit {
  const char* name;  // camelCase, as scripts and JSON spell it
  bool logging;      // false: byte 1 (settings), true: byte 2 (logging)
  int bit;           // 7 = most significant
};

// Every named bit, settings first, each byte from bit 7 down (the reference's order).
std::span<const ToggleBit> toggleBits();
const ToggleBit* findToggle(std::string_view name);
// "collisionAvoidance, positioning, …": for error messages.
std::string toggleNames();

bool isSet(const Toggles& t, const ToggleBit& bit);
void setBit(Toggles& t, const ToggleBit& bit, bool on);

}  // namespace pitwall::alphabot
