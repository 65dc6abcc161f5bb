// `pitwall completion bash|zsh` (docs/cli.md "Shell completion"): the completion script of the
// shell, generated from the command line's own definition — every command, its options, which
// of them take a value — so it cannot fall behind. The build writes both into the package
// (packaging/packaging.cmake). What only the words say is in kValues below: which values are
// layouts, files or a fixed list.
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "engine/cli/build_info.hpp"
#include "engine/cli/options.hpp"
#include "engine/sim/track.hpp"

namespace pitwall::cli {

namespace {

enum class Kind { Text, Files, LuaFiles, Dirs, Layout, Words };
struct Values {
  Kind kind = Kind::Text;
  std::vector<std::string> words;
};

// What an option's or a positional's value is, by its name (an option not here takes free text).
const std::map<std::string, Values>& valuesByName() {
  static const std::map<std::string, Values> values{
      {"--track", {Kind::Layout, {}}},
      {"layout", {Kind::Layout, {}}},
      {"--log-level", {Kind::Words, {"debug", "info", "warn", "error", "off"}}},
      {"--svg", {Kind::Files, {}}},
      {"--out", {Kind::Files, {}}},
      {"--paper", {Kind::Words, {"a4", "a3"}}},
      {"piece", {Kind::Layout, {}}},
      {"--results", {Kind::Files, {}}},
      {"--record", {Kind::Files, {}}},
      {"--ghost", {Kind::Files, {}}},
      {"--history", {Kind::Files, {}}},
      {"--mqtt-password-file", {Kind::Files, {}}},
      {"--mqtt-ca", {Kind::Files, {}}},
      {"file", {Kind::Files, {}}},
      {"dir", {Kind::Dirs, {}}},
      {"script", {Kind::LuaFiles, {}}},
      {"paths", {Kind::LuaFiles, {}}},
      {"kind", {Kind::Words, {"mindroad", "alphabot"}}},
      {"protocol", {Kind::Words, {"anki", "mindroad", "alphabot", "alphabot-ble"}}},
      {"shell", {Kind::Words, {"bash", "zsh"}}},
  };
  return values;
}

Values valuesOf(const std::string& name) {
  auto it = valuesByName().find(name);
  return it == valuesByName().end() ? Values{} : it->second;
}

struct Opt {
  std::vector<std::string> names;  // "-q", "--quiet"
  std::string key;                 // the long name, or the positional's name
  std::string help;
  bool value = false;   // takes a value
  bool repeat = false;  // may be given more than once
};

struct Cmd {
  std::string path;  // "" (pitwall itself), "run", "track show"
  std::string name, help;
  std::vector<Opt> options, positionals;
  std::vector<Cmd> subs;
};

std::string firstLine(std::string s) {
  if (auto nl = s.find('\n'); nl != std::string::npos) s.resize(nl);
  return s;
}

Cmd model(const CLI::App& app, const std::string& path) {
  Cmd c{path, app.get_name(), firstLine(app.get_description()), {}, {}, {}};
  for (const CLI::Option* o : app.get_options()) {
    Opt opt;
    for (const auto& s : o->get_snames()) opt.names.push_back("-" + s);
    for (const auto& l : o->get_lnames()) opt.names.push_back("--" + l);
    opt.key = o->get_lnames().empty() ? o->get_name() : "--" + o->get_lnames().front();
    opt.help = firstLine(o->get_description());
    // --view's value may be left out: completing it as a flag keeps the next word the script.
    opt.value = o->get_expected_min() > 0;
    opt.repeat = o->get_items_expected_max() > 1 ||
                 o->get_multi_option_policy() == CLI::MultiOptionPolicy::TakeAll;
    if (o->get_positional())
      c.positionals.push_back(opt);
    else
      c.options.push_back(opt);
  }
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    c.subs.push_back(model(*sub, path.empty() ? sub->get_name() : path + " " + sub->get_name()));
  return c;
}

// The options of `pitwall` itself that every command takes (they fall through): not its --help.
std::vector<Opt> globalOptions(const Cmd& root) {
  std::vector<Opt> options;
  for (const auto& o : root.options)
    if (o.key != "--help") options.push_back(o);
  return options;
}

std::string join(const std::vector<std::string>& words, const char* sep = " ") {
  std::string s;
  for (const auto& w : words) s += (s.empty() ? "" : sep) + w;
  return s;
}

void each(const Cmd& c, const std::function<void(const Cmd&)>& f) {
  f(c);
  for (const auto& s : c.subs) each(s, f);
}

// ---- bash ------------------------------------------------------------------------------------

// The COMPREPLY line for a value of this kind (cur is the word being completed).
std::string bashValues(const Values& v) {
  switch (v.kind) {
    case Kind::Layout:
      return "_pitwall_words \"$_pitwall_layouts\"; _pitwall_files";
    case Kind::Words:
      return "_pitwall_words \"" + join(v.words) + "\"";
    case Kind::Files:
      return "_pitwall_files";
    case Kind::LuaFiles:
      return "_pitwall_files lua";
    case Kind::Dirs:
      return "_pitwall_files /";
    case Kind::Text:
      break;
  }
  return ":";
}

std::string bash(const Cmd& root) {
  std::ostringstream s;
  s << "# bash completion for pitwall, generated by `pitwall completion bash` (" << build::version
    << "): do not edit\n"
    << "_pitwall_layouts=\"" << join(sim::layoutNames()) << "\"\n\n"
    << "_pitwall_words() { COMPREPLY+=($(compgen -W \"$1\" -- \"$cur\")); }\n"
    << "# files (only *.EXT given an extension, none given /) and folders, completed as paths\n"
    << "_pitwall_files() {\n"
    << "  compopt -o filenames 2>/dev/null\n"
    << "  local f\n"
    << "  while IFS= read -r f; do [ -d \"$f\" ] || COMPREPLY+=(\"$f\"); done < <(\n"
    << "    if [ -n \"${1:-}\" ]; then compgen -f -X \"!*.$1\" -- \"$cur\"; "
       "else compgen -f -- \"$cur\"; fi)\n"
    << "  while IFS= read -r f; do COMPREPLY+=(\"$f\"); done < <(compgen -d -S / -- \"$cur\")\n"
    << "  [ ${#COMPREPLY[@]} -eq 1 ] && [ \"${COMPREPLY[0]: -1}\" = / ] && compopt -o nospace "
       "2>/dev/null\n"
    << "  return 0\n}\n\n";

  // Which words are commands, which options take a value: the walk over the line needs both.
  s << "_pitwall_is_command() {\n  case \"$1/$2\" in\n";
  each(root, [&](const Cmd& c) {
    for (const auto& sub : c.subs)
      s << "    \"" << c.path << "/" << sub.name << "\") return 0 ;;\n";
  });
  s << "  esac\n  return 1\n}\n\n";

  s << "_pitwall_takes_value() {\n  case \"$1/$2\" in\n";
  for (const auto& o : root.options)
    if (o.value)
      for (const auto& n : o.names) s << "    */" << n << ") return 0 ;;\n";
  each(root, [&](const Cmd& c) {
    if (c.path.empty()) return;
    for (const auto& o : c.options)
      if (o.value)
        for (const auto& n : o.names) s << "    \"" << c.path << "/" << n << "\") return 0 ;;\n";
  });
  s << "  esac\n  return 1\n}\n\n";

  s << "_pitwall() {\n"
    << "  local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD-1]}\n"
    << "  local cmd=\"\" npos=0 i w\n"
    << "  COMPREPLY=()\n"
    << "  for ((i = 1; i < COMP_CWORD; i++)); do\n"
    << "    w=${COMP_WORDS[i]}\n"
    << "    case \"$w\" in\n"
    << "      --) break ;;\n"
    << "      -*=*) ;;\n"
    << "      -*) _pitwall_takes_value \"$cmd\" \"$w\" && ((i++)) ;;\n"
    << "      *) if _pitwall_is_command \"$cmd\" \"$w\"; then cmd=${cmd:+$cmd }$w; "
       "else ((npos++)); fi ;;\n"
    << "    esac\n"
    << "  done\n";
  // The value of the option before the cursor.
  s << "  if [[ \"$prev\" == -* ]] && _pitwall_takes_value \"$cmd\" \"$prev\"; then\n"
    << "    case \"$prev\" in\n";
  std::map<std::string, std::string> byOption;  // every option name: one kind for all commands
  each(root, [&](const Cmd& c) {
    for (const auto& o : c.options)
      if (o.value)
        for (const auto& n : o.names) byOption[n] = bashValues(valuesOf(o.key));
  });
  for (const auto& [name, line] : byOption)
    if (line != ":") s << "      " << name << ") " << line << " ;;\n";
  s << "    esac\n    return 0\n  fi\n";
  // Options of the command (and the ones every command takes).
  s << "  if [[ \"$cur\" == -* ]]; then\n    case \"$cmd\" in\n";
  std::vector<std::string> global;
  for (const auto& o : globalOptions(root))
    for (const auto& n : o.names) global.push_back(n);
  each(root, [&](const Cmd& c) {
    std::vector<std::string> names;
    for (const auto& o : c.options)
      for (const auto& n : o.names) names.push_back(n);
    if (!c.path.empty()) names.insert(names.end(), global.begin(), global.end());
    s << "      \"" << c.path << "\") _pitwall_words \"" << join(names) << "\" ;;\n";
  });
  s << "    esac\n    return 0\n  fi\n";
  // Commands, or the command's arguments.
  s << "  case \"$cmd\" in\n";
  each(root, [&](const Cmd& c) {
    if (!c.subs.empty()) {
      std::vector<std::string> names;
      for (const auto& sub : c.subs) names.push_back(sub.name);
      s << "    \"" << c.path << "\") _pitwall_words \"" << join(names) << "\" ;;\n";
      return;
    }
    if (c.positionals.empty()) return;
    s << "    \"" << c.path << "\")\n      case $npos in\n";
    for (std::size_t i = 0; i < c.positionals.size(); ++i) {
      const auto& p = c.positionals[i];
      const bool last = i + 1 == c.positionals.size();
      s << "        " << (last && p.repeat ? "*" : std::to_string(i)) << ") "
        << bashValues(valuesOf(p.key)) << " ;;\n";
    }
    s << "      esac ;;\n";
  });
  s << "  esac\n  return 0\n}\ncomplete -F _pitwall pitwall\n";
  return s.str();
}

// ---- zsh -------------------------------------------------------------------------------------

// Text inside an _arguments spec in single quotes: ' closes the quote, [ ] : are its syntax.
std::string zq(const std::string& text) {
  std::string out;
  for (char ch : text) {
    if (ch == '\'')
      out += "'\\''";
    else if (ch == '[' || ch == ']' || ch == ':' || ch == '\\')
      out += std::string("\\") + ch;
    else
      out += ch;
  }
  return out;
}

std::string zshAction(const Values& v) {
  switch (v.kind) {
    case Kind::Layout:
      return "_pitwall_layouts";
    case Kind::Words:
      return "(" + join(v.words) + ")";
    case Kind::Files:
      return "_files";
    case Kind::LuaFiles:
      return "_files -g \"*.lua(-.)\"";
    case Kind::Dirs:
      return "_files -/";
    case Kind::Text:
      break;
  }
  return " ";
}

std::string funcName(const Cmd& c) {
  std::string f = "_pitwall";
  for (char ch : c.path) f += (ch == ' ' || ch == '-') ? '_' : ch;
  return f;
}

void zshSpecs(std::ostream& s, const std::vector<Opt>& options) {
  for (const auto& o : options) {
    std::string exclude;
    if (o.names.size() > 1) exclude = "(" + join(o.names) + ")";
    if (o.repeat) exclude = "*";
    for (const auto& n : o.names) {
      s << "    '" << exclude << n << "[" << zq(o.help) << "]";
      if (o.value) s << ":" << zq(o.key.substr(2)) << ":" << zq(zshAction(valuesOf(o.key)));
      s << "' \\\n";
    }
  }
}

void zshFunction(std::ostringstream& s, const Cmd& c, const std::vector<Opt>& global) {
  s << funcName(c) << "() {\n  local curcontext=\"$curcontext\" state line ret=1\n"
    << "  _arguments -C -s \\\n";
  zshSpecs(s, c.options);
  if (!c.path.empty()) zshSpecs(s, global);
  if (!c.subs.empty()) {
    s << "    ': :->command' '*:: :->args' && ret=0\n  case $state in\n"
      << "    command)\n      local -a commands=(\n";
    for (const auto& sub : c.subs) s << "        '" << zq(sub.name) << ":" << zq(sub.help) << "'\n";
    s << "      )\n      _describe -t commands '" << (c.path.empty() ? "pitwall" : c.path)
      << " command' commands && ret=0 ;;\n"
      << "    args)\n      curcontext=\"${curcontext%:*:*}:pitwall-$words[1]:\"\n"
      << "      case $words[1] in\n";
    for (const auto& sub : c.subs)
      s << "        " << sub.name << ") " << funcName(sub) << " && ret=0 ;;\n";
    s << "      esac ;;\n  esac\n  return ret\n}\n\n";
  } else {
    for (std::size_t i = 0; i < c.positionals.size(); ++i) {
      const auto& p = c.positionals[i];
      const bool rest = p.repeat && i + 1 == c.positionals.size();
      s << "    '" << (rest ? "*" : std::to_string(i + 1)) << ":" << zq(p.key) << ":"
        << zq(zshAction(valuesOf(p.key))) << "' \\\n";
    }
    s << "    && ret=0\n  return ret\n}\n\n";
  }
  for (const auto& sub : c.subs) zshFunction(s, sub, global);
}

std::string zsh(const Cmd& root) {
  std::ostringstream s;
  s << "#compdef pitwall\n# zsh completion for pitwall, generated by `pitwall completion zsh` ("
    << build::version << "): do not edit\n\n"
    << "_pitwall_layouts() {\n  _alternative 'layouts:layout:(" << join(sim::layoutNames())
    << ")' 'files:layout file:_files'\n}\n\n";
  zshFunction(s, root, globalOptions(root));
  s << "if [ \"$funcstack[1]\" = \"_pitwall\" ]; then\n  _pitwall \"$@\"\nelse\n"
    << "  compdef _pitwall pitwall\nfi\n";
  return s.str();
}

}  // namespace

Command addCompletionCommand(CLI::App& app) {
  auto shell = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand(
      "completion", "Print the shell completion script: source <(pitwall completion bash)");
  cmd->add_option("shell", *shell, "bash or zsh")
      ->required()
      ->check(CLI::IsMember({"bash", "zsh"}));
  return {cmd, [&app, shell] {
            const Cmd root = model(app, "");
            std::cout << (*shell == "bash" ? bash(root) : zsh(root));
            return 0;
          }};
}

}  // namespace pitwall::cli
