#include "engine/cli/standings_keeping.hpp"

#include <filesystem>
#include <iostream>

#include "engine/cli/fail.hpp"

namespace pitwall::cli {

CLI::Validator standingsFile() {
  return CLI::Validator(
      [](std::string& file) -> std::string {
        if (!file.empty()) return "";
        return "the standings database's file name is empty: give a file, or leave --db out "
               "for the default ($PITWALL_DB, else $XDG_DATA_HOME/pitwall/standings.db)";
      },
      "FILE");
}

void addStandingsOptions(CLI::App* cmd, std::string& db, bool& noDb, const std::string& what) {
  cmd->add_option("--db", db,
                  "Keep " + what +
                      " in this standings database (default: $PITWALL_DB, else "
                      "$XDG_DATA_HOME/pitwall/standings.db; docs/league.md \"Standings\")")
      ->check(standingsFile());
  cmd->add_flag("--no-db", noDb, "Keep nothing in the standings database");
}

Result<std::unique_ptr<standings::Keeper>, std::string> openStandings(
    const std::string& db, bool noDb, standings::Event event, const std::string& command,
    const std::vector<std::pair<std::string, std::string>>& outputs,
    std::optional<int> racingWaitMs) {
  if (noDb) return std::unique_ptr<standings::Keeper>();
  const std::string path = db.empty() ? standings::defaultPath() : db;
  std::error_code ec;
  const auto at = std::filesystem::weakly_canonical(path, ec);
  for (const auto& [option, file] : outputs) {
    std::error_code ec2, ec3;
    if (!file.empty() && !path.empty() &&
        (std::filesystem::weakly_canonical(file, ec2) == at ||
         std::filesystem::equivalent(file, path, ec3)))  // (a hard link too)
      return Unexpected{option + " " + file + " is the standings database (" + path +
                        "): it would be written over; give another file, or --no-db"};
  }
  auto opened = standings::Keeper::open(path, std::move(event), racingWaitMs);
  if (opened || !db.empty()) return opened;
  std::cerr << "pitwall " << command << ": " << opened.error()
            << ": nothing of this run is kept in the standings\n";
  return std::unique_ptr<standings::Keeper>();
}

bool finishStandings(standings::Keeper* keeper, const std::string& command,
                     const std::function<void(const std::string&)>& told) {
  if (!keeper) return true;
  if (auto problem = keeper->finish()) {
    fail(command, *problem, 1);
    return false;
  }
  if (keeper->written() > 0)
    told("kept in the standings: " + keeper->path() + " (pitwall standings --db " + keeper->path() +
         ")");
  return true;
}

}  // namespace pitwall::cli
