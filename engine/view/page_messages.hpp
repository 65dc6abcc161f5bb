#pragma once
// What one page sends over its WebSocket (docs/view.md "Messages from a page"), and the answers
// it gets: replay controls ({"type":"control"}), and — with the feed's seats (--humans) — the
// controller page's seat, drive and leave. One PageMessages a WebSocket: the connection is one
// holder of a seat ("phone#3"), and closing it (closed()) lets go of the seat, which slows its
// car to a stop. The server only moves the bytes: it hands each text message to receive() and
// writes the answers that nextAnswer() gives before the page's next update.
//
// Nothing a page sends may throw out of the loop (that would end the run with the cars at
// speed): every field's type is checked before it is read, the control's handler is guarded, a
// flood is dropped (a seat's holder that floods loses nothing but the extra), and answers are
// bounded (kMaxAnswers, the oldest dropped; the same refusal of a drive message at most once a
// second).
#include <cstddef>
#include <deque>
#include <map>
#include <optional>
#include <string>

#include "engine/core/loop.hpp"
#include "engine/core/token_bucket.hpp"
#include "engine/view/feed.hpp"
#include "engine/view/pairing.hpp"

namespace pitwall::view {

class PageMessages {
 public:
  // The controller page sends 10 drive messages a second and one on each change of its controls
  // (at most 30 a second); more is a flood, dropped without an answer each.
  static constexpr RateLimit kLimit{.perSecond = 40, .burst = 20};
  static constexpr std::size_t kMaxAnswers = 8;  // waiting for a slow page; the oldest go first

  // `pairing`: the join code a seat, a drive and a control need (none: no code needed);
  // `client`: the key this page's wrong codes are counted by (Pairing::clientKey).
  PageMessages(Loop& loop, Feed& feed, std::string holder, Pairing* pairing = nullptr,
               std::string client = {})
      : loop_(loop),
        feed_(feed),
        holder_(std::move(holder)),
        pairing_(pairing),
        client_(std::move(client)),
        paired_(!pairing || !pairing->required()) {}

  void receive(const std::string& text) noexcept;
  // A join code the page brought (its /ws?code=…, or a message's "code"): pairs the page, or
  // answers why not (wrong, locked out). True when the page is paired.
  bool pair(std::string_view code);
  bool paired() const { return paired_; }
  // A message for this page alone, written before its next update (the join code, for the
  // race view on this machine).
  void tell(std::string text) { answer(std::move(text)); }
  // The page went (closed, lost, stalled): its seat, if it held one, is let go.
  void closed();
  // The next answer to write, oldest first; none when all are written.
  std::optional<std::string> nextAnswer();
  const std::string& holder() const { return holder_; }

 private:
  void control(const nlohmann::json& m);
  void seat(const nlohmann::json& m);
  void drive(const nlohmann::json& m);
  void refuseDrive(const std::string& why);
  void leave();
  void answer(std::string text);
  bool mayDrive(const nlohmann::json& m, bool quiet);

  Loop& loop_;
  Feed& feed_;
  std::string holder_;
  Pairing* pairing_;
  std::string client_;
  bool paired_;
  std::deque<std::string> answers_;
  TokenBucket bucket_;                  // the page's messages (kLimit)
  bool flooding_ = false;               // said once a flood
  std::map<std::string, double> said_;  // refusals of drive messages, and when each was said
};

}  // namespace pitwall::view
