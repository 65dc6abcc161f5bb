#include "engine/core/suggest.hpp"

#include <algorithm>
#include <cctype>
#include <vector>

namespace pitwall {

namespace {
char lower(char c) {
  return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
}
}  // namespace

std::size_t editDistance(std::string_view a, std::string_view b) {
  // Three rows of the Damerau (optimal string alignment) table: i-2, i-1 and i.
  const std::size_t n = b.size();
  std::vector<std::size_t> before(n + 1), prev(n + 1), cur(n + 1);
  for (std::size_t j = 0; j <= n; ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= n; ++j) {
      const bool same = lower(a[i - 1]) == lower(b[j - 1]);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (same ? 0 : 1)});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) &&
          lower(a[i - 2]) == lower(b[j - 1]))
        cur[j] = std::min(cur[j], before[j - 2] + 1);
    }
    std::swap(before, prev);
    std::swap(prev, cur);
  }
  return prev[n];
}

std::optional<std::string> nearest(std::string_view word, std::span<const std::string> candidates) {
  if (word.empty()) return std::nullopt;
  const std::size_t limit = std::max<std::size_t>(1, word.size() / 3);
  std::optional<std::string> best;
  std::size_t bestDistance = limit + 1;
  for (const auto& c : candidates) {
    if (c == word) continue;  // the word itself is no suggestion (in another case it is the best)
    std::size_t d = editDistance(word, c);
    const bool prefix =
        c.size() > word.size() && std::equal(word.begin(), word.end(), c.begin(),
                                             [](char x, char y) { return lower(x) == lower(y); });
    if (prefix && word.size() >= 2) d = std::min(d, limit);
    if (d < bestDistance) {
      bestDistance = d;
      best = c;
    }
  }
  return best;
}

std::string didYouMean(std::string_view word, std::span<const std::string> candidates) {
  auto n = nearest(word, candidates);
  return n ? "; did you mean " + *n + "?" : std::string();
}

}  // namespace pitwall
