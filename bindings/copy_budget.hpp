#pragma once
// What the engine copies out of a Lua world for itself (pitwall.view.race's table, the rows of
// pitwall.writeResults) is bounded and counted against the world's memory cap (docs/safety.md):
// a string referenced many times costs at each place it is copied, so one 1 MiB string in a
// table 1500 times would be 1.5 GB outside Lua's allocator, and seconds of C++ work that neither
// the budget nor Ctrl-C can interrupt. A copy is refused as soon as it passes the smaller of its
// own limit and what the world's cap still leaves, with a sentence naming both.
#include <lua.hpp>

#include <algorithm>
#include <cstddef>
#include <string>

#include "bindings/lua_args.hpp"
#include "bindings/script_host.hpp"

namespace pitwall::lua {

class CopyBudget {
 public:
  // `what` names the API in the refusal ("pitwall.view.race"); `max` is its own limit in bytes;
  // `replacing`: bytes of the world's `outside` charge that this copy replaces once it is made.
  CopyBudget(lua_State* L, std::string what, std::size_t max, std::size_t replacing = 0)
      : what_(std::move(what)), max_(max) {
    const sandbox::Memory& memory = ScriptHost::from(L).memory();
    if (memory.limit != 0) {
      capMb_ = memory.limit >> 20;
      const std::size_t held = memory.used + memory.outside - std::min(replacing, memory.outside);
      capLeft_ = memory.limit > held ? memory.limit - held : 0;
      capped_ = capLeft_ < max_;
    }
  }

  // `bytes` more are copied, for the value at `where` ("race.rows[3].name"): past the limit, a
  // LuaError that says which limit, how much and what to do.
  void add(std::size_t bytes, const std::string& where) {
    bytes_ += bytes;
    if (bytes_ <= (capped_ ? capLeft_ : max_)) return;
    const std::string at = where.size() > 120 ? where.substr(0, 120) + "…" : where;
    const std::string advice =
        "send less: a long text, or one value referenced many times, counts at every place it "
        "is used";
    if (capped_)
      throw LuaError(what_ + ": the copy passed the " + size(capLeft_) + " that the script's " +
                     "memory limit of " + std::to_string(capMb_) + " MB still leaves (" +
                     std::to_string(bytes_) + " bytes by " + at + "); " + advice +
                     ", or raise --lua-memory");
    throw LuaError(what_ + ": the data is more than " + size(max_) + " (" + std::to_string(bytes_) +
                   " bytes by " + at + "); " + advice);
  }
  std::size_t bytes() const { return bytes_; }

 private:
  static std::string size(std::size_t bytes) {
    if (bytes >= (std::size_t{1} << 20) && bytes % (std::size_t{1} << 20) == 0)
      return std::to_string(bytes >> 20) + " MiB";
    return std::to_string(bytes) + " bytes";
  }
  std::string what_;
  std::size_t max_;
  std::size_t capMb_ = 0;
  std::size_t capLeft_ = 0;
  bool capped_ = false;
  std::size_t bytes_ = 0;
};

}  // namespace pitwall::lua
