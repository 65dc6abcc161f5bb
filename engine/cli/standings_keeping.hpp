#pragma once
// How a command that races keeps its results in the standings (docs/league.md "Standings"):
// `run`, `league` and `league merge` take --db FILE and --no-db alike, open the database before
// anything races and say at the end where the results are, or what could not be written.
#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/core/result.hpp"
#include "engine/standings/keeper.hpp"

namespace pitwall::cli {

// --db's check: a file name, not an empty one (`--db ''` or `--db "$UNSET"` would otherwise
// mean the default database, silently).
CLI::Validator standingsFile();

// --db FILE and --no-db on `cmd`; `what` says what is kept ("the league", "the races' results").
void addStandingsOptions(CLI::App* cmd, std::string& db, bool& noDb, const std::string& what);

// The keeper of `event`'s races: none with --no-db. A file named with --db that cannot be opened
// is the error (the command refuses before anything races); the default one that cannot be, or
// none at all (no PITWALL_DB, XDG_DATA_HOME or HOME), is said on stderr as `command`'s, and the
// command races on without keeping.
// `outputs`: the command's other files (--record, --results, --report), named by their option:
// the database being one of them is refused (it would be written over). `racingWaitMs`: see
// standings::Keeper::open.
Result<std::unique_ptr<standings::Keeper>, std::string> openStandings(
    const std::string& db, bool noDb, standings::Event event, const std::string& command,
    const std::vector<std::pair<std::string, std::string>>& outputs,
    std::optional<int> racingWaitMs);

// Writes what is held and ends the event; says where the results are kept (`told`: on stderr as
// `command`'s) or the sentence of what could not be written. True when everything was kept.
bool finishStandings(standings::Keeper* keeper, const std::string& command,
                     const std::function<void(const std::string&)>& told);

}  // namespace pitwall::cli
