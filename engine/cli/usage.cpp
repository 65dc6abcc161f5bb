#include "engine/cli/usage.hpp"

#include <algorithm>
#include <cctype>

#include "engine/core/printable.hpp"
#include "engine/core/suggest.hpp"

namespace pitwall::cli {

namespace {

std::vector<const CLI::App*> subcommandsOf(const CLI::App& app) {
  return app.get_subcommands([](const CLI::App*) { return true; });
}

std::string pathOf(const CLI::App& cmd) {
  std::string path = cmd.get_name();
  for (const CLI::App* p = cmd.get_parent(); p; p = p->get_parent())
    path = p->get_name() + " " + path;
  return path;
}

// A word that is a number (encode's "set-offset -23.5"), not an option.
bool isNumber(const std::string& w) {
  return w.size() > 1 && w[0] == '-' &&
         (std::isdigit(static_cast<unsigned char>(w[1])) || w[1] == '.');
}

const CLI::Option* findOption(const CLI::App& cmd, const std::string& name) {
  for (const CLI::App* a = &cmd; a; a = a->get_parent())
    if (const CLI::Option* o = a->get_option_no_throw(name)) return o;
  return nullptr;
}

}  // namespace

void printCommands(const CLI::App& app, std::ostream& out) {
  out << app.get_description() << "\n\nUsage: " << app.get_name()
      << " COMMAND [OPTIONS] [ARGS]\n\nCommands:\n";
  std::size_t width = 0;
  for (const CLI::App* sub : subcommandsOf(app)) width = std::max(width, sub->get_name().size());
  for (const CLI::App* sub : subcommandsOf(app)) {
    std::string line = sub->get_description();
    if (auto nl = line.find('\n'); nl != std::string::npos) line.resize(nl);
    out << "  " << sub->get_name() << std::string(width + 2 - sub->get_name().size(), ' ') << line
        << "\n";
  }
  out << "\n`" << app.get_name() << " COMMAND --help` shows a command's options; `"
      << app.get_name() << " --help` the options every command takes; `" << app.get_name()
      << " --version` the version.\n";
}

std::vector<std::string> longOptions(const CLI::App& cmd) {
  std::vector<std::string> names;
  for (const CLI::App* a = &cmd; a; a = a->get_parent())
    for (const CLI::Option* o : a->get_options())
      for (const auto& l : o->get_lnames()) names.push_back("--" + l);
  return names;
}

std::optional<std::string> explainRefusal(const CLI::App& app, int argc, const char* const* argv) {
  const CLI::App* cur = &app;
  bool commandTaken = false;  // a command without subcommands takes positional arguments
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--") break;
    if (arg.size() > 1 && arg[0] == '-' && !isNumber(arg)) {
      const std::string name = arg.substr(0, arg.find('='));
      if (name.rfind("--", 0) != 0) {  // short options: -q, -h; -qh and values are CLI11's
        if (const CLI::Option* o = findOption(*cur, name.substr(0, 2));
            o && o->get_expected_min() > 0 && arg.size() == 2)
          ++i;
        continue;
      }
      const CLI::Option* o = findOption(*cur, name);
      if (!o) {
        const std::string path = pathOf(*cur);
        return path + ": unknown option " + printable(name, 80) +
               (name.size() <= 80 ? didYouMean(name, longOptions(*cur)) : "") + " (`" + path +
               " --help` lists the options)";
      }
      if (o->get_expected_min() > 0 && arg.find('=') == std::string::npos) ++i;  // its value
      continue;
    }
    if (commandTaken) continue;
    auto subs = subcommandsOf(*cur);
    if (subs.empty()) {
      commandTaken = true;
      continue;
    }
    auto found = std::find_if(subs.begin(), subs.end(),
                              [&](const CLI::App* s) { return s->check_name(arg); });
    if (found != subs.end()) {
      cur = *found;
      continue;
    }
    // a command with subcommands that takes arguments too (league DIR, league merge FILE)
    const auto options = cur->get_options();
    if (std::any_of(options.begin(), options.end(),
                    [](const CLI::Option* o) { return o->get_positional(); })) {
      commandTaken = true;
      continue;
    }
    std::vector<std::string> names;
    for (const CLI::App* s : subs) names.push_back(s->get_name());
    const std::string path = pathOf(*cur);
    return path + ": unknown command '" + printable(arg, 80) + "'" +
           (arg.size() <= 80 ? didYouMean(arg, names) : "") + " (`" + path +
           (cur == &app ? "` lists the commands)" : " --help` lists its commands)");
  }
  return std::nullopt;
}

}  // namespace pitwall::cli
