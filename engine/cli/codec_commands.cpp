// pitwall decode / pitwall encode: the codecs from the shell.
#include <cctype>
#include <iostream>
#include <memory>

#include "engine/cli/commands.hpp"
#include "engine/cli/fail.hpp"
#include "engine/cli/options.hpp"
#include "engine/core/hex.hpp"
#include "engine/protocol/anki/codec.hpp"
#include "engine/protocol/anki/command_text.hpp"
#include "engine/protocol/anki/message_json.hpp"
#include "engine/record/recorder.hpp"

namespace pitwall::cli {

namespace {

constexpr const char* kProtocols = "anki, mindroad, alphabot";

// "06 24 e8", "06:24:e8", "0624e8" and "0x06 0x24" all give the same bytes.
Result<std::vector<std::uint8_t>, std::string> parseHex(const std::vector<std::string>& words) {
  std::string digits;
  for (const auto& w : words) {
    for (std::size_t i = 0; i < w.size(); ++i) {
      char c = w[i];
      if (c == '0' && i + 1 < w.size() && (w[i + 1] == 'x' || w[i + 1] == 'X') &&
          (i == 0 || !std::isxdigit(static_cast<unsigned char>(w[i - 1])))) {
        ++i;
        continue;
      }
      if (std::isxdigit(static_cast<unsigned char>(c)))
        digits += c;
      else if (c != ' ' && c != ':' && c != ',' && c != '-')
        return Unexpected{std::string("'") + c + "' is not a hex digit in \"" + w + "\""};
    }
  }
  if (digits.empty())
    return Unexpected{std::string("no bytes given; write them as hex, e.g. \"01 17\"")};
  return fromHex(digits);  // only digits are left: the error can only be an odd count
}

}  // namespace

int decode(const std::string& protocol, const std::vector<std::string>& hex) {
  // `pitwall decode alphabot-ble CHARACTERISTIC HEX`: the first word names the characteristic.
  bool alphabotBle = protocol == "alphabot-ble";
  if (protocol != "anki" && protocol != "mindroad" && protocol != "alphabot" && !alphabotBle) {
    return fail("decode", "unknown protocol '" + protocol + "'; known: " + std::string(kProtocols) +
                              ", alphabot-ble");
  }
  std::vector<std::string> words = hex;
  std::string side;
  if (alphabotBle) {
    if (words.size() < 2) {
      return fail("decode",
                  "alphabot-ble needs a characteristic name and the bytes, e.g. pitwall decode "
                  "alphabot-ble sensor \"80 2d 64 00 00\"");
    }
    side = words.front();
    words.erase(words.begin());
  }
  auto bytes = parseHex(words);
  if (!bytes) {
    return fail("decode", bytes.error());
  }
  if (protocol == "mindroad") return decodeMindroad(*bytes);
  if (protocol == "alphabot" || alphabotBle) return decodeAlphabot(*bytes, side);
  // As the receiver reads it: a car takes the short command forms too (decodeCommand), and bytes
  // past a layout are shown, not dropped (anki-overdrive.md **Decision**).
  auto message = anki::decodeCommand(*bytes);
  if (!message) {
    return fail("decode", message.error().message());
  }
  nlohmann::json json = anki::toJson(*message);
  if (auto extra = anki::extraBytes(*bytes); !extra.empty()) json["extra_bytes"] = toHex(extra);
  std::cout << json.dump() << "\n";
  return 0;
}

int encode(const std::string& protocol, const std::vector<std::string>& words) {
  if (protocol == "mindroad") return encodeMindroad(words);
  if (protocol == "alphabot") return encodeAlphabot(words);
  if (protocol != "anki") {
    return fail("encode", "unknown protocol '" + protocol + "'; known: " + std::string(kProtocols));
  }
  auto message = anki::parseCommand(words);
  if (!message) {
    return fail("encode", message.error());
  }
  std::cout << toHex(anki::encode(*message).span()) << "\n";
  return 0;
}

namespace {
struct CodecArguments {
  std::string protocol;
  std::vector<std::string> words;
};
}  // namespace

Command addDecodeCommand(CLI::App& app) {
  auto args = std::make_shared<CodecArguments>();
  auto* cmd = app.add_subcommand("decode", "Decode one frame: pitwall decode anki \"01 17\"");
  cmd->add_option("protocol", args->protocol, "Protocol (anki, mindroad, alphabot, alphabot-ble)")
      ->required();
  cmd->add_option("hex", args->words, "The frame's bytes in hex")->required();
  cmd->positionals_at_end(false);  // negative numbers are arguments, not options
  return {cmd, [args] { return cli::decode(args->protocol, args->words); }};
}

Command addEncodeCommand(CLI::App& app) {
  auto args = std::make_shared<CodecArguments>();
  auto* cmd =
      app.add_subcommand("encode", "Encode one command: pitwall encode anki set-speed 600 1000");
  cmd->add_option("protocol", args->protocol, "Protocol (anki, mindroad, alphabot)")->required();
  cmd->add_option("message", args->words, "The command and its arguments")->required();
  std::string forms;
  for (const auto& f : anki::commandForms()) forms += "\n  " + f;
  cmd->footer("Commands (anki):" + forms);
  cmd->positionals_at_end(false);  // set-offset -23.5: -23.5 is an argument, not an option
  return {cmd, [args] { return cli::encode(args->protocol, args->words); }};
}

}  // namespace pitwall::cli
