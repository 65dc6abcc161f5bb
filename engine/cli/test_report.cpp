#include "engine/cli/test_report.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string_view>

#include "engine/core/printable.hpp"

namespace pitwall::cli {

namespace {

using Status = ScenarioResult::Status;

std::vector<std::string_view> lines(std::string_view text) {
  std::vector<std::string_view> out;
  while (!text.empty()) {
    auto nl = text.find('\n');
    out.push_back(text.substr(0, nl));
    if (nl == std::string_view::npos) break;
    text.remove_prefix(nl + 1);
  }
  return out;
}

std::string timing(const ScenarioResult& r) {
  char text[96];
  std::snprintf(text, sizeof text, "%.1f s simulated in %.0f ms", r.simulated, r.wall * 1000);
  return text;
}

std::string replay(const ReportedScenario& s) {
  return "seed " + std::to_string(s.result.seed) + ": " + printable(s.replay) + " replays it";
}

std::string testLine(const ScenarioResult& r) {
  return r.line > 0 ? r.file + ":" + std::to_string(r.line) : "";
}

// The message names a place other than the test's line (a helper module, the library): the
// test's line is said too.
bool messageElsewhere(const ScenarioResult& r) {
  return r.line > 0 && !std::string_view(r.message).starts_with(testLine(r) + ":");
}

// The traceback says more than the message's own place: a user function called from the test.
bool tracebackWorthShowing(const ScenarioResult& r, bool verbose) {
  return verbose ? !r.traceback.empty() : r.traceback.size() > 1;
}

// The lines of a failure's report, as the person's report, TAP and JUnit all carry them.
std::vector<std::string> failureLines(const ReportedScenario& s, bool verbose) {
  const ScenarioResult& r = s.result;
  std::vector<std::string> out;
  for (auto l : lines(r.message)) out.push_back(printable(l));
  if (messageElsewhere(r)) out.push_back("in the test at " + testLine(r));
  if (tracebackWorthShowing(r, verbose)) {
    out.emplace_back("stack traceback:");
    for (const auto& f : r.traceback) out.push_back("  " + printable(f));
  }
  if (!r.waiting.empty()) {
    char at[64];
    std::snprintf(at, sizeof at, "at %.1f s of virtual time:", r.stoppedAt);
    out.emplace_back(at);
    for (const auto& w : r.waiting) out.push_back("  " + printable(w));
  }
  out.push_back(replay(s));
  return out;
}

const char* statusWord(Status s) {
  switch (s) {
    case Status::Passed:
      return "passed";
    case Status::Failed:
      return "expectation";
    case Status::Errored:
      return "error";
    case Status::TimedOut:
      return "timeout";
    case Status::Crashed:
      return "crash";
  }
  return "error";
}

// XML 1.0 character data: what printable() leaves is UTF-8 without control characters.
std::string xml(std::string_view text) {
  std::string out;
  for (auto l : lines(text)) {
    std::string shown = printable(l);
    // Well-formed UTF-8 that XML 1.0 still forbids: the noncharacters U+FFFE and U+FFFF.
    for (std::string_view bad : {"\xEF\xBF\xBE", "\xEF\xBF\xBF"})
      for (auto at = shown.find(bad); at != std::string::npos; at = shown.find(bad, at))
        shown.replace(at, bad.size(), bad.back() == '\xBE' ? "\\uFFFE" : "\\uFFFF");
    out += markupEscaped(shown);
    out += '\n';
  }
  if (!out.empty()) out.pop_back();
  return out;
}

std::string yamlString(std::string_view text) {
  return nlohmann::json(printable(text)).dump();
}

std::string join(const std::vector<std::string>& parts) {
  std::string out;
  for (const auto& p : parts) out += p + "\n";
  return out;
}

}  // namespace

void printScenario(std::ostream& out, const ReportedScenario& s, bool verbose) {
  const ScenarioResult& r = s.result;
  out << r.output;
  if (!r.output.empty() && r.output.back() != '\n') out << "\n";
  if (r.passed()) {
    out << "ok    " << s.path << " (" << timing(r) << ")\n";
  } else {
    out << "FAIL  " << s.path << " (" << timing(r) << ")\n";
    for (const auto& l : failureLines(s, verbose)) out << "      " << l << "\n";
  }
  out.flush();
}

void printTapPlan(std::ostream& out, std::size_t count) {
  out << "TAP version 14\n1.." << count << "\n";
  out.flush();
}

void printTapPoint(std::ostream& out, std::size_t number, const ReportedScenario& s) {
  const ScenarioResult& r = s.result;
  for (auto l : lines(r.output)) out << "# " << printable(l) << "\n";
  std::string description = printable(s.path);  // '#' would start a directive: \#
  for (auto at = description.find('#'); at != std::string::npos; at = description.find('#', at + 2))
    description.insert(at, 1, '\\');
  out << (r.passed() ? "ok " : "not ok ") << number << " - " << description << "\n";
  if (!r.passed()) {
    out << "  ---\n";
    out << "  message: " << yamlString(r.message) << "\n";
    out << "  severity: " << (r.status == Status::Failed ? "fail" : "error") << "\n";
    out << "  kind: " << statusWord(r.status) << "\n";
    if (r.line > 0)
      out << "  at:\n    file: " << yamlString(r.file) << "\n    line: " << r.line << "\n";
    out << "  seed: " << r.seed << "\n";
    char numbers[96];
    std::snprintf(numbers, sizeof numbers, "  simulated_s: %.3f\n  duration_ms: %.0f\n",
                  r.simulated, r.wall * 1000);
    out << numbers;
    if (!r.waiting.empty()) {
      out << "  waiting:\n";
      for (const auto& w : r.waiting) out << "    - " << yamlString(w) << "\n";
    }
    if (!r.traceback.empty()) {
      out << "  traceback:\n";
      for (const auto& f : r.traceback) out << "    - " << yamlString(f) << "\n";
    }
    out << "  ...\n";
  }
  out.flush();
}

void writeJUnit(std::ostream& out, const std::vector<ReportedScenario>& scenarios,
                double wallSeconds) {
  std::size_t failures = 0, errors = 0;
  for (const auto& s : scenarios) {
    if (s.result.status == Status::Failed) ++failures;
    if (s.result.status != Status::Failed && !s.result.passed()) ++errors;
  }
  char host[256] = "localhost";
  gethostname(host, sizeof host - 1);
  std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%S", std::gmtime(&now));
  auto seconds = [](double s) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3f", s);
    return std::string(text);
  };
  std::string counts = "tests=\"" + std::to_string(scenarios.size()) + "\" failures=\"" +
                       std::to_string(failures) + "\" errors=\"" + std::to_string(errors) +
                       "\" skipped=\"0\" time=\"" + seconds(wallSeconds) + "\"";
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out << "<testsuites name=\"pitwall test\" " << counts << ">\n";
  out << "  <testsuite name=\"pitwall test\" " << counts << " timestamp=\"" << stamp
      << "\" hostname=\"" << xml(host) << "\">\n";
  for (const auto& s : scenarios) {
    const ScenarioResult& r = s.result;
    std::filesystem::path path(s.path);
    std::string folder = path.parent_path().lexically_normal().generic_string();
    for (char& c : folder)
      if (c == '/') c = '.';
    while (!folder.empty() && folder.front() == '.') folder.erase(0, 1);
    if (folder.empty()) folder = "scenarios";
    out << "    <testcase classname=\"" << xml(folder) << "\" name=\"" << xml(path.stem().string())
        << "\" file=\"" << xml(s.path) << "\"";
    if (r.line > 0) out << " line=\"" << r.line << "\"";
    out << " time=\"" << seconds(r.wall) << "\"";
    if (r.passed() && r.output.empty()) {
      out << "/>\n";
      continue;
    }
    out << ">\n";
    if (!r.passed()) {
      const char* element = r.status == Status::Failed ? "failure" : "error";
      std::string first = std::string(lines(r.message).empty() ? "" : lines(r.message)[0]);
      out << "      <" << element << " message=\"" << xml(first) << "\" type=\""
          << statusWord(r.status) << "\">" << xml(join(failureLines(s, true))) << "</" << element
          << ">\n";
    }
    if (!r.output.empty()) out << "      <system-out>" << xml(r.output) << "</system-out>\n";
    out << "    </testcase>\n";
  }
  out << "  </testsuite>\n</testsuites>\n";
}

}  // namespace pitwall::cli
