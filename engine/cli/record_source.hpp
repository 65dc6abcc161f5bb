#pragma once
// A record given on the command line, opened for playing (pitwall replay, pitwall compare): a
// file (not a folder, pipe or device), a capture without times given its times, scanned once
// (RecordSummary) and put back to its start; its bad lines told on stderr, the first 20 each
// with its number and why, then a count.
#include <fstream>
#include <istream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <variant>

#include "engine/record/record_reader.hpp"

namespace pitwall::cli {

struct RecordSource {
  std::string file;
  std::ifstream fileIn;
  std::istringstream captured;  // a capture without times, with its times
  std::istream* in = nullptr;   // the frames, at their start: fileIn or captured
  RecordSummary summary;
};

// The record, or the exit status after `pitwall COMMAND: why` on stderr (2: not a record to
// read; 1: a record with no frame). `interval`: --interval, a capture's seconds between frames.
std::variant<std::unique_ptr<RecordSource>, int> openRecord(const std::string& command,
                                                            const std::string& file,
                                                            std::optional<double> interval);

}  // namespace pitwall::cli
