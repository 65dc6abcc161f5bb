// bytes ⇄ messages for the Anki Overdrive protocol (anki-overdrive.md "Frame", "Controller →
// vehicle", "Vehicle → controller"; seed 000 §4.3.2, §4.3.4, §4.3.5).
//
// message_fields.hpp says everything about each message: id, name, the size bytes it may have,
// and its fields in wire order. Reading and writing both walk that one field list, so the two
// directions cannot drift apart. decode() reads a position update, the frame cars send most,
// straight away; any other id is looked up in a 256-entry table built at compile time. No
// allocation, no exceptions, no strings.
//
// A frame longer than the longest layout of its id is read by that layout; extraBytes() gives the
// rest (anki-overdrive.md **Decision**: drive-sdk and the seed's code read fixed offsets and
// ignore trailing bytes, and a firmware that appends a field must not lose its position updates).
#include "engine/protocol/anki/codec.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cstring>
#include <type_traits>
#include <utility>

#include "engine/core/hex.hpp"
#include "engine/protocol/anki/message_fields.hpp"

namespace pitwall::anki {
namespace {

using fields::Described;
using fields::IsOptional;
using fields::Layout;
using fields::Sizes;
using fields::Spec;

// A field that is a plain number on the wire (bool and enums are bytes with their own rules).
template <class V>
concept Number = std::is_arithmetic_v<V> && !std::is_same_v<V, bool>;

// anki-overdrive.md: multi-byte fields are little-endian, floats IEEE-754 single precision.
template <Number V>
V fromWire(std::array<std::uint8_t, sizeof(V)> bytes) {
  if constexpr (std::endian::native == std::endian::big) std::ranges::reverse(bytes);
  return std::bit_cast<V>(bytes);
}

template <Number V>
std::array<std::uint8_t, sizeof(V)> toWire(V v) {
  auto bytes = std::bit_cast<std::array<std::uint8_t, sizeof(V)>>(v);
  if constexpr (std::endian::native == std::endian::big) std::ranges::reverse(bytes);
  return bytes;
}

// Reads fields from a frame whose length is one of its layout's (checked first; a longer frame is
// cut to its longest layout before it gets here).
class Reader {
 public:
  Reader(std::span<const std::uint8_t> frame, bool long_form)
      : frame_(frame), long_form_(long_form) {}

  template <Number V>
  void get(V& v) {
    assert(at_ + sizeof(V) <= frame_.size());
    std::array<std::uint8_t, sizeof(V)> bytes;
    std::memcpy(bytes.data(), frame_.data() + at_, sizeof(V));
    v = fromWire<V>(bytes);
    at_ += sizeof(V);
  }
  void get(bool& v) {
    std::uint8_t byte = 0;
    get(byte);
    v = byte != 0;
  }
  template <class E>
  requires std::is_enum_v<E>
  void get(E& v) {  // any byte is kept, also one outside the enum
    std::underlying_type_t<E> u{};
    get(u);
    v = static_cast<E>(u);
  }
  // Fields of an optional tail or middle (older/newer firmware) are on the wire in the long form
  // only; see fields::Sizes.
  template <class V>
  void get(std::optional<V>& v) {
    if (long_form_) get(v.emplace());
  }
  template <class V, std::size_t N>
  void get(std::array<V, N>& a) {
    for (auto& x : a) get(x);
  }
  template <Described T>
  void get(T& m) {
    fields::forEach<T>([&](const auto& field) { get(m.*field.member); });
  }

 private:
  std::span<const std::uint8_t> frame_;
  std::size_t at_ = 2;  // after [size][id]
  bool long_form_;
};

// Writes a frame [size][id][payload]; finish() fills in the size byte.
class Writer {
 public:
  Writer(std::uint8_t id, bool long_form) : long_form_(long_form) {
    frame_.bytes[1] = id;
    frame_.length = 2;
  }

  template <Number V>
  void put(V v) {
    assert(frame_.length + sizeof(V) <= Frame::kMax);
    const auto bytes = toWire(v);
    std::memcpy(frame_.bytes.data() + frame_.length, bytes.data(), sizeof(V));
    frame_.length = static_cast<std::uint8_t>(frame_.length + sizeof(V));
  }
  void put(bool v) { put(static_cast<std::uint8_t>(v ? 1 : 0)); }
  template <class E>
  requires std::is_enum_v<E>
  void put(E v) { put(static_cast<std::underlying_type_t<E>>(v)); }
  // In the long form every optional field is written; one left empty goes out as zero.
  template <class V>
  void put(const std::optional<V>& v) {
    if (long_form_) put(v.value_or(V{}));
  }
  template <class V, std::size_t N>
  void put(const std::array<V, N>& a) {
    for (const auto& x : a) put(x);
  }
  template <Described T>
  void put(const T& m) {
    fields::forEach<T>([&](const auto& field) { put(m.*field.member); });
  }
  // Bytes of the layout that carry no field.
  void zeros(std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) put(std::uint8_t{0});
  }

  Frame finish() {
    frame_.bytes[0] = static_cast<std::uint8_t>(frame_.length - 1);
    return frame_;
  }

 private:
  Frame frame_;
  bool long_form_;
};

// Written long as soon as one optional field is set.
template <class T>
bool longForm(const T& m) {
  bool any_set = false;
  fields::forEach<T>([&](const auto& field) {
    const auto& value = m.*field.member;
    if constexpr (IsOptional<std::remove_cvref_t<decltype(value)>>::value) {
      any_set = any_set || value.has_value();
    }
  });
  return any_set;
}

// ---- dispatch by id ----

constexpr std::size_t kKnownKinds = std::variant_size_v<Message> - 1;  // all but Unknown
static_assert(std::is_same_v<std::variant_alternative_t<kKnownKinds, Message>, Unknown>,
              "Unknown must stay the last alternative of Message");

template <std::size_t I>
using Kind = std::variant_alternative_t<I, Message>;

using Decoded = Result<Message, DecodeError>;

// Where a decoded message starts: the result is initialised from this constant, then the message
// is emplaced into it and its fields read straight into the returned value (NRVO). A message put
// together on the stack and copied into the result costs a store-forwarding stall instead (the
// copy's wide loads wait for the narrow stores that wrote the fields): that was about half of
// decode's time (docs/performance.md "Decode").
constexpr Message kNoMessage{};

// `inline` lets GCC take the body into decode() too (measured: ≈ 0.5 ns less per position update).
template <class T>
inline Decoded readFrame(std::span<const std::uint8_t> frame) {
  constexpr Sizes sizes = Spec<T>::layout.sizes;
  Decoded out{kNoMessage};
  Reader reader(frame, sizes.shorter != sizes.longer && frame.size() == sizes.longer + 1u);
  reader.get(out.value().template emplace<T>());
  return out;
}

template <class T>
Frame writeFrame(const T& m) {
  constexpr Layout layout = Spec<T>::layout;
  Writer writer(layout.id, longForm(m));
  writer.put(m);
  writer.zeros(layout.zeros_after);
  return writer.finish();
}

// A frame of exactly T's one layout: decodeAny's checks, all passed, for one known id.
template <class T>
bool isWhole(std::span<const std::uint8_t> frame) {
  constexpr Layout layout = Spec<T>::layout;
  static_assert(layout.sizes.shorter == layout.sizes.longer, "a message with one layout only");
  return frame.size() == layout.sizes.shorter + 1u && frame[0] == layout.sizes.shorter &&
         frame[1] == layout.id;
}

struct Entry {
  Layout layout{0, {}, {0, 0}};
  Decoded (*read)(std::span<const std::uint8_t>) = nullptr;  // nullptr: the id is not known
};

// kById[id]: what the id is and how to read it, built from the Specs (message_fields.hpp).
constexpr std::array<Entry, 256> kById = [] {
  std::array<Entry, 256> table{};
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((table[Spec<Kind<I>>::layout.id] = Entry{Spec<Kind<I>>::layout, &readFrame<Kind<I>>}), ...);
  }
  (std::make_index_sequence<kKnownKinds>{});
  return table;
}();

// Every Spec must have its own id: a clash would silently shadow a message.
constexpr bool idsAreDistinct() {
  std::array<bool, 256> seen{};
  bool distinct = true;
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((distinct = distinct && !std::exchange(seen[Spec<Kind<I>>::layout.id], true)), ...);
  }
  (std::make_index_sequence<kKnownKinds>{});
  return distinct;
}
static_assert(idsAreDistinct(), "two message kinds share one id");

Decoded fail(DecodeError::Kind kind, std::uint8_t id, std::size_t expected, std::size_t received) {
  return Unexpected{DecodeError{kind, id, expected, received}};
}

std::string bytes(std::size_t n) {
  return std::to_string(n) + (n == 1 ? " byte" : " bytes");
}

std::string idText(std::uint8_t id) {
  const auto& e = kById[id];
  return "message " + hexByte(id) +
         (e.read ? " (" + std::string(e.layout.name) + ")" : std::string());
}

// Any frame: the checks in order, then the reader found by id. Out of line (see decode()).
[[gnu::noinline]] Decoded decodeAny(std::span<const std::uint8_t> frame) {
  using K = DecodeError::Kind;
  const std::size_t n = frame.size();
  if (n == 0) return fail(K::Empty, 0, 2, 0);
  const std::uint8_t id = n >= 2 ? frame[1] : 0;
  if (n > Frame::kMax) return fail(K::TooBig, id, Frame::kMax, n);
  // anki-overdrive.md "Frame": the size byte counts the id and the payload (= length − 1).
  if (std::size_t{frame[0]} != n - 1) {
    return fail(K::SizeMismatch, id, std::size_t{frame[0]} + 1, n);
  }
  if (n < 2) return fail(K::TooShort, 0, 2, n);  // a lone size byte 00: no id at all

  const Entry& entry = kById[id];
  if (entry.read == nullptr) {  // anki-overdrive.md **Decision**: unknown ids are kept whole
    Decoded out{kNoMessage};
    auto& unknown = out.value().emplace<Unknown>();
    unknown.id = id;
    std::memcpy(unknown.raw.bytes.data(), frame.data(), n);
    unknown.raw.length = static_cast<std::uint8_t>(n);
    return out;
  }
  const std::uint8_t size = frame[0];
  const auto [shorter, longer] = entry.layout.sizes;
  // anki-overdrive.md **Decision**: read by the longest layout; extraBytes() has the rest.
  if (size > longer) return entry.read(frame.first(longer + 1u));
  // Between an older and a newer form counts as a cut-short newer form.
  if (size != shorter && size != longer) {
    return fail(K::TooShort, id, std::size_t{size < shorter ? shorter : longer} + 1, n);
  }
  return entry.read(frame);
}

}  // namespace

Result<Message, DecodeError> decode(std::span<const std::uint8_t> frame) {
  // The frame cars send most (docs/performance.md "Decode"): read straight away, without the
  // table lookup and the indirect call every other id goes through, and without the setup the
  // rest of decoding needs (which is why decodeAny is kept out of line).
  if (isWhole<PositionUpdate>(frame)) return readFrame<PositionUpdate>(frame);
  return decodeAny(frame);
}

static_assert(Spec<PositionUpdate>::layout.sizes.longer + 1u == kPositionUpdateFrameSize);

std::span<const std::uint8_t> extraBytes(std::span<const std::uint8_t> frame) {
  const std::size_t n = frame.size();
  if (n < 2 || n > Frame::kMax || frame[0] != n - 1) return {};  // decode() refuses it
  const Entry& entry = kById[frame[1]];
  if (entry.read == nullptr) return {};  // an unknown id: no layout, all of it is in Unknown::raw
  const std::size_t whole = entry.layout.sizes.longer + 1u;
  return n > whole ? frame.subspan(whole) : std::span<const std::uint8_t>{};
}

namespace {

// A command form shorter than its layout that real firmware obeys: the frame's size byte. The
// fields it leaves out are the layout's last ones, taken as zero (their defaults).
struct ShortForm {
  std::uint8_t id;
  std::uint8_t size;
};
// anki-overdrive.md **Decision**: set speed without the respect-limit byte (py-drivesdk's
// set_speed and stop send `05 24 <speed> <accel>`; real cars obey it).
constexpr std::array kShortForms{ShortForm{id::kSetSpeed, 5}};

static_assert(
    [] {
      for (const auto& form : kShortForms) {
        if (kById[form.id].read == nullptr || form.size >= kById[form.id].layout.sizes.shorter)
          return false;
      }
      return true;
    }(),
    "a short form must be shorter than the shortest layout of a known id");

}  // namespace

Result<Message, DecodeError> decodeCommand(std::span<const std::uint8_t> frame) {
  auto decoded = decode(frame);
  if (decoded || decoded.error().kind != DecodeError::Kind::TooShort || frame.size() < 2)
    return decoded;
  for (const auto& form : kShortForms) {
    if (frame[1] != form.id || frame[0] != form.size) continue;
    // The frame completed with zero bytes up to the shortest layout, its size byte to match.
    Frame whole;
    std::memcpy(whole.bytes.data(), frame.data(), frame.size());
    const std::uint8_t size = kById[form.id].layout.sizes.shorter;
    whole.bytes[0] = size;
    whole.length = static_cast<std::uint8_t>(size + 1);
    return decode(whole.span());
  }
  return decoded;
}

Frame encode(const Message& message) {
  return std::visit(
      []<class T>(const T& m) -> Frame {
        if constexpr (std::is_same_v<T, Unknown>) {
          if (m.raw.length > 0) return m.raw;
          return Writer(m.id, false).finish();  // an Unknown built by hand without bytes
        } else {
          return writeFrame(m);
        }
      },
      message);
}

std::string_view name(const Message& message) {
  return std::visit(
      []<class T>(const T&) -> std::string_view {
        if constexpr (std::is_same_v<T, Unknown>) {
          return "unknown";
        } else {
          return Spec<T>::layout.name;
        }
      },
      message);
}

std::uint8_t messageId(const Message& message) {
  return std::visit(
      []<class T>(const T& m) -> std::uint8_t {
        if constexpr (std::is_same_v<T, Unknown>) {
          return m.id;
        } else {
          return Spec<T>::layout.id;
        }
      },
      message);
}

std::string DecodeError::message() const {
  switch (kind) {
    case Kind::Empty:
      return "empty frame: no bytes received, a frame needs at least a size byte and an id";
    case Kind::TooBig:
      return idText(id) + " is " + bytes(received) + " long, more than the " + bytes(Frame::kMax) +
             " a frame may have";
    case Kind::SizeMismatch:
      return (received < 2 ? std::string("frame without an id") : idText(id)) +
             ": its size byte says " + bytes(expected) + " but " + bytes(received) + " arrived";
    case Kind::TooShort:
      if (received < 2) {
        return "frame without an id: " + bytes(received) + " received, a frame needs at least " +
               bytes(expected) + " (size and id)";
      }
      return idText(id) + " is too short: " + bytes(received) + " received, its layout needs " +
             bytes(expected);
  }
  return "decode error " + std::to_string(static_cast<int>(kind));
}

}  // namespace pitwall::anki
