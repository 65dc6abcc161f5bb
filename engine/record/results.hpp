#pragma once
// Race results to a file (`pitwall run --results FILE`): JSON or CSV by the file's extension.
// The race library builds the rows; this writes them (pitwall.writeResults, docs/lua-api.md).
#include <string>
#include <variant>
#include <vector>

#include "engine/core/result.hpp"

namespace pitwall::results {

enum class Format { Json, Csv };

// The format for a path by its extension (.json, .csv; any case), or a sentence saying why not.
Result<Format, std::string> formatOf(const std::string& path);

// A cell: nothing (JSON null, empty in CSV), a number, text, or a truth value.
using Cell = std::variant<std::monostate, double, std::string, bool>;
struct Table {
  std::vector<std::string> columns;
  std::vector<std::vector<Cell>> rows;  // each as long as columns
};

// JSON: an array of objects keyed by column, in column order; CSV: a header line, then one line
// per row (RFC 4180 quoting). Numbers are rounded to the millisecond (three decimals: times are
// seconds); those that are whole then print without a fraction.
std::string render(const Table& table, Format format);
// The path has a known extension and its folder takes a new file (checked before a race, so a
// typo does not cost the results afterwards); a sentence naming the problem otherwise.
Result<bool, std::string> writable(const std::string& path);
// Writes atomically enough for a results file: the whole text, then a rename over the path.
Result<bool, std::string> write(const std::string& path, const Table& table);
// The same for any text (a league's JSON, its HTML report); `what` names it in the sentence.
Result<bool, std::string> writeText(const std::string& path, const std::string& text,
                                    const std::string& what);

}  // namespace pitwall::results
