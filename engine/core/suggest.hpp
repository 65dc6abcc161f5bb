#pragma once
// "Did you mean …?": the one way every layer suggests the name a person probably meant — an
// unknown command (`pitwall rn`), a misspelled method (`car:setSped`), an unknown option key
// (`race.laps{lapz = 3}`), a driver that does not exist (`drivers.load("crusier")`).
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace pitwall {

// The edit distance between a and b, counting an insertion, a deletion, a substitution or a
// swap of two neighbouring letters as one edit ("optimal string alignment"); letters compare
// without case, so `SetSpeed` is no edit from `setSpeed`: the nearest of all.
std::size_t editDistance(std::string_view a, std::string_view b);

// The candidate nearest to `word`, when it is near enough to be what was meant: at most
// max(1, length / 3) edits away (two for "crusier" → "cruiser" would be fine; "x" → "run" is
// not), or `word` is a prefix of it. Ties go to the first candidate. nullopt when none is.
std::optional<std::string> nearest(std::string_view word, std::span<const std::string> candidates);

// "; did you mean <nearest>?" or "" — to append to an error that names `word`.
std::string didYouMean(std::string_view word, std::span<const std::string> candidates);

}  // namespace pitwall
