#pragma once
// A value or an error, for code paths where failure is an ordinary outcome (codecs, parsers,
// validation). Exceptions are kept for the edges where a user gets told (see STYLE.md).
#include <cassert>
#include <utility>
#include <variant>

namespace pitwall {

// The constructor (not an aggregate) so that `Unexpected(e)` also compiles with clang 14, which
// lacks C++20's parenthesized aggregate initialization.
template <class E>
struct Unexpected {
  Unexpected(E e) : error(std::move(e)) {}
  E error;
};
template <class E>
Unexpected(E) -> Unexpected<E>;

template <class T, class E>
class Result {
 public:
  Result(T value) : v_(std::in_place_index<0>, std::move(value)) {}
  template <class G>
  Result(Unexpected<G> e) : v_(std::in_place_index<1>, std::move(e.error)) {}

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() & {
    assert(ok());
    return std::get<0>(v_);
  }
  const T& value() const& {
    assert(ok());
    return std::get<0>(v_);
  }
  T&& value() && {
    assert(ok());
    return std::get<0>(std::move(v_));
  }
  const E& error() const {
    assert(!ok());
    return std::get<1>(v_);
  }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() { return value(); }
  const T& operator*() const { return value(); }

 private:
  std::variant<T, E> v_;
};

}  // namespace pitwall
