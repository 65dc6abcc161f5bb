#pragma once
// A point many listeners watch (a car's connection, the cars that join a fleet, every frame of
// a fleet): Signal<Args...>. connect() returns a Subscription that owns the slot: the callback
// dies with its owner (Defold's rule, docs/architecture.md), so listeners come and go in any
// order, which hand-chained single callbacks allowed only in reverse.
//
// The rules, pinned by tests/unit/core/signal_test.cpp:
// - slots are called in the order they were connected;
// - a slot connected during an emit is not called by that emit (the next one calls it);
// - a slot disconnected during an emit is not called after its disconnection, by that emit or
//   any other; a slot that disconnects itself finishes its call (its captures live until it
//   returns);
// - an emit inside an emit runs the slots connected at its own start;
// - a signal destroyed before its subscriptions leaves them harmless (they disconnect nothing),
//   even when it is destroyed by one of its own slots during an emit.
// Single slots stay where one listener is the contract (Link::onFrame: the model owns its link).
#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

namespace pitwall {

namespace detail {
// What a Subscription reaches of its signal, whatever the signal's arguments.
struct SlotList {
  virtual ~SlotList() = default;
  virtual void drop(std::uint64_t id) = 0;
  virtual bool holds(std::uint64_t id) const = 0;
};
}  // namespace detail

// Owns one slot of a signal: moving it moves the ownership, destroying it (or disconnect())
// removes the slot. Empty when default-made, moved from, or disconnected.
class [[nodiscard]] Subscription {
 public:
  Subscription() = default;
  Subscription(std::weak_ptr<detail::SlotList> list, std::uint64_t id)
      : list_(std::move(list)), id_(id) {}
  Subscription(Subscription&& other) noexcept
      : list_(std::move(other.list_)), id_(std::exchange(other.id_, 0)) {}
  Subscription& operator=(Subscription&& other) noexcept {
    if (this != &other) {
      disconnect();
      list_ = std::move(other.list_);
      id_ = std::exchange(other.id_, 0);
    }
    return *this;
  }
  Subscription(const Subscription&) = delete;
  Subscription& operator=(const Subscription&) = delete;
  ~Subscription() { disconnect(); }

  void disconnect() {
    if (auto list = list_.lock()) list->drop(id_);
    list_.reset();
    id_ = 0;
  }
  // The slot is still connected to a signal that still exists.
  bool connected() const {
    auto list = list_.lock();
    return list && list->holds(id_);
  }

 private:
  std::weak_ptr<detail::SlotList> list_;
  std::uint64_t id_ = 0;
};

template <class... Args>
class Signal {
 public:
  using Slot = std::function<void(Args...)>;

  Signal() = default;
  // Destroyed by one of its own slots during an emit: the list lives on until that emit (the
  // outermost) returns, so the emit needs no count of its own on the list.
  ~Signal() {
    if (list_->emitting > 0) list_->self = list_;
  }
  Signal(const Signal&) = delete;
  Signal& operator=(const Signal&) = delete;

  Subscription connect(Slot fn) {
    auto id = list_->nextId++;
    list_->slots.push_back(std::make_shared<Entry>(Entry{id, std::move(fn), true}));
    return Subscription(list_, id);
  }

  // Calls the slots connected now, in order (see the rules above).
  void emit(Args... args) const {
    if (list_->slots.empty()) return;  // the hot path of a signal nobody watches: inlined
    emitToSlots(args...);
  }
  void operator()(Args... args) const { emit(args...); }

  std::size_t size() const {
    std::size_t n = 0;
    for (const auto& e : list_->slots) n += e->live ? 1 : 0;
    return n;
  }
  bool empty() const { return size() == 0; }

 private:
  [[gnu::noinline]] void emitToSlots(Args... args) const {
    // A slot may destroy the signal: then the list keeps itself (~Signal) until this emit ends,
    // and no atomic count pair is paid on every emit to guard against it.
    List* list = list_.get();
    const std::size_t n = list->slots.size();
    ++list->emitting;
    struct Done {
      List& list;
      ~Done() {
        if (--list.emitting > 0) return;
        if (list.dirty) list.compact();
        if (list.self) auto last = std::move(list.self);  // the signal is gone: so is the list
      }
    } done{*list};
    for (std::size_t i = 0; i < n; ++i) {
      // Lives through its call without a count of its own (no atomic pair per slot and emit):
      // entries are destroyed only by compact(), never while an emit runs, and a slot connected
      // meanwhile may move the vector of pointers, not the entry.
      Entry& entry = *list->slots[i];
      if (entry.live) entry.fn(args...);
    }
  }

  struct Entry {
    std::uint64_t id;
    Slot fn;
    bool live;
  };
  struct List final : detail::SlotList {
    // Entries leave only outside an emit (compact), so an emit's indexes stay valid.
    std::vector<std::shared_ptr<Entry>> slots;
    std::uint64_t nextId = 1;
    int emitting = 0;
    bool dirty = false;
    std::shared_ptr<List> self;  // set by ~Signal during an emit, released when it ends

    void drop(std::uint64_t id) override {
      for (auto it = slots.begin(); it != slots.end(); ++it) {
        if ((*it)->id != id || !(*it)->live) continue;
        (*it)->live = false;
        if (emitting > 0) {
          dirty = true;
          return;
        }
        auto dead = std::move(*it);  // its callback dies after the list is consistent again
        slots.erase(it);
        return;
      }
    }
    bool holds(std::uint64_t id) const override {
      for (const auto& e : slots)
        if (e->id == id) return e->live;
      return false;
    }
    void compact() {
      dirty = false;
      std::vector<std::shared_ptr<Entry>> kept, dead;
      for (auto& e : slots) (e->live ? kept : dead).push_back(std::move(e));
      slots = std::move(kept);
      // `dead` goes last: a callback's destructor may touch this list
    }
  };
  std::shared_ptr<List> list_ = std::make_shared<List>();
};

}  // namespace pitwall
