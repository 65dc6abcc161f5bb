#pragma once
// Text from outside — a line of a file, a script's option key, a car's name — made fit for one
// line of an error or a log: the one way every layer shows text it cannot trust.
#include <cstddef>
#include <string>
#include <string_view>

namespace pitwall {

// The length of the well-formed UTF-8 character of 2..4 bytes at the start of `s` (RFC 3629: no
// overlong form, no surrogate, nothing beyond U+10FFFF), or 0 when there is none.
std::size_t utf8Length(std::string_view s);

// Printable ASCII and well-formed UTF-8 as they are (`vitésse`), every other byte (control
// characters, bytes that are not UTF-8) as \xNN; at most `maxBytes` bytes of that (so an error
// stays short however hostile the text), then "…" when some of the text was left out.
std::string printable(std::string_view text, std::size_t maxBytes = std::string_view::npos);

// Text for XML or HTML character data and attribute values: & < > " ' as entities, the rest as
// it is (give it printable() text: markup takes no control characters).
std::string markupEscaped(std::string_view text);

}  // namespace pitwall
