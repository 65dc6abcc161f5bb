#include "engine/cli/record_source.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "engine/cli/fail.hpp"
#include "engine/core/log.hpp"
#include "engine/record/capture.hpp"

namespace pitwall::cli {

namespace {
constexpr std::size_t kBadLinesShown = 20;  // then a count: a binary file is not 10⁶ lines
static_assert(kBadLinesShown <= kBadLinesKept, "the summary keeps the lines shown");

std::string who(const std::string& command) {
  return command == "replay" ? "a replay" : "`pitwall " + command + "`";
}
}  // namespace

std::variant<std::unique_ptr<RecordSource>, int> openRecord(const std::string& command,
                                                            const std::string& file,
                                                            std::optional<double> interval) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) {
    return fail(command, file + " is a folder; give a --record file");
  }
  if (std::filesystem::exists(file, ec) && !std::filesystem::is_regular_file(file, ec)) {
    return fail(command, file + " is not a file (a pipe or a device); " + who(command) +
                             " reads its record twice, from a file: save it to a file first");
  }
  auto source = std::make_unique<RecordSource>();
  source->file = file;
  source->fileIn.open(file, std::ios::binary);
  if (!source->fileIn) {
    return fail(command, "cannot read " + file + ": " + std::strerror(errno));
  }
  // A capture without times (docs/cli.md "Captures without times") is read whole and given
  // times; a record is played from its file.
  source->in = &source->fileIn;
  std::optional<BadLines> captureBad;
  if (RecordKind kind = recordKind(source->fileIn); kind != RecordKind::Timed) {
    auto timed = timeCapture(source->fileIn, kind, CaptureTiming{interval});
    if (!timed) {
      return fail(command, file + ": " + timed.error());
    }
    log::info(command, file +
                           (kind == RecordKind::IndexedJson
                                ? "'s \"t\" counts its frames (0, 1, 2, …), not seconds: "
                                : " is a capture without times: ") +
                           timed->how);
    source->captured.str(std::move(timed->record));
    captureBad = std::move(timed->bad);
    source->in = &source->captured;
  } else if (interval) {
    return fail(command,
                "--interval states the time between the frames of a capture without times, and " +
                    file + " has its times (\"t\"): leave it out");
  }
  std::istream& in = *source->in;
  // One pass to count and check; the frames are read again as they are played (RecordPlayer):
  // neither pass keeps more than a line, a frame and the first bad lines.
  RecordSummary& record = source->summary;
  record = scanRecord(in);
  if (in.bad()) {
    return fail(command, "cannot read " + file + ": " + std::strerror(errno));
  }
  if (captureBad) record.bad = std::move(*captureBad);  // the capture's lines, not ours
  const auto& bad = record.bad;
  for (std::size_t i = 0; i < bad.first.size() && i < kBadLinesShown; ++i)
    std::cerr << file << ":" << bad.first[i].line << ": " << bad.first[i].why << "\n";
  if (bad.count > kBadLinesShown)
    std::cerr << file << ": " << bad.count - kBadLinesShown << " more bad lines\n";
  if (record.frames == 0) {
    return fail(command,
                file +
                    (bad.count == 0 ? " is empty"
                                    : " has no line that is a frame (" + std::to_string(bad.count) +
                                          " bad lines)") +
                    "; a record is what `pitwall run --record FILE` writes",
                1);
  }
  if (bad.count > 0)
    log::warn(command, std::to_string(bad.count) + " bad line" + (bad.count == 1 ? "" : "s") +
                           " of " + file + " left out; " +
                           (command == "replay" ? "replaying" : "reading") + " the " +
                           std::to_string(record.frames) + " frames that are whole");
  in.clear();
  in.seekg(0);
  if (!in) {
    return fail(command, "cannot read " + file + " from its start again (" + who(command) +
                             " reads a record twice): give a file, not a pipe");
  }
  return source;
}

}  // namespace pitwall::cli
