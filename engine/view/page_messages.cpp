#include "engine/view/page_messages.hpp"

#include <cmath>

#include "engine/core/log.hpp"
#include "engine/drive/seats.hpp"

namespace pitwall::view {

namespace {

constexpr double kErrorEvery = 1.0;  // s: the same refusal of a drive message, said again
constexpr const char* kDrivingOff = "driving is off in this run: start it with --humans N";
constexpr const char* kNeedCode =
    "this race view needs its join code to drive or control: open the address the terminal "
    "and the race view show (/drive?code=…), or give the code";

const nlohmann::json* field(const nlohmann::json& m, const char* name) {
  auto it = m.find(name);
  return it == m.end() ? nullptr : &*it;
}

std::string error(const std::string& why) {
  return nlohmann::json{{"type", "error"}, {"message", why}}.dump(
      -1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// A whole number from a message, within [lo, hi]; none for anything else (text, 1.5, 1e300).
std::optional<int> whole(const nlohmann::json* v, int lo, int hi) {
  if (!v || !v->is_number()) return std::nullopt;
  const double d = v->get<double>();
  if (!std::isfinite(d) || d != std::floor(d) || d < lo || d > hi) return std::nullopt;
  return static_cast<int>(d);
}

}  // namespace

void PageMessages::receive(const std::string& text) noexcept {
  try {
    nlohmann::json m = nlohmann::json::parse(text, nullptr, false);
    const nlohmann::json* type = m.is_object() ? field(m, "type") : nullptr;
    if (!type || !type->is_string()) return;
    const std::string& kind = type->get_ref<const std::string&>();
    // letting go is always taken: a page that flooded may still leave its seat
    if (kind == "leave") return leave();
    if (kind != "control" && kind != "seat" && kind != "drive") return;  // not for the view
    if (!bucket_.take(kLimit, loop_.now())) {
      if (!flooding_)
        answer(error("too many messages: a page may send " +
                     std::to_string(static_cast<int>(kLimit.perSecond)) +
                     " a second; the others are dropped"));
      flooding_ = true;
      return;
    }
    flooding_ = false;
    if (!mayDrive(m, kind == "drive")) return;
    if (kind == "control") return control(m);
    if (kind == "seat") return seat(m);
    if (kind == "drive") return drive(m);
  } catch (const std::exception& e) {  // none expected: the last guard of the loop
    log::warn("view", std::string("a page's message was dropped: ") + e.what());
  }
}

bool PageMessages::pair(std::string_view code) {
  if (paired_) return true;
  auto ok = pairing_->check(client_, code, loop_.seconds());
  if (!ok) {
    answer(error(ok.error()));
    return false;
  }
  paired_ = true;
  answer(nlohmann::json{{"type", "paired"}}.dump());
  return true;
}

// A page that is not paired drives nothing: its message's "code" pairs it, or it is told why
// not (a drive message's refusal at most once a second, as every refusal of a drive).
bool PageMessages::mayDrive(const nlohmann::json& m, bool quiet) {
  if (paired_) return true;
  const nlohmann::json* code = field(m, "code");
  if (!code || !code->is_string()) {
    if (quiet)
      refuseDrive(kNeedCode);
    else
      answer(error(kNeedCode));
    return false;
  }
  return pair(code->get_ref<const std::string&>());
}

void PageMessages::closed() {
  if (drive::Seats* seats = feed_.seats()) seats->release(holder_, "the phone disconnected");
}

std::optional<std::string> PageMessages::nextAnswer() {
  if (answers_.empty()) return std::nullopt;
  std::string text = std::move(answers_.front());
  answers_.pop_front();
  return text;
}

void PageMessages::answer(std::string text) {
  answers_.push_back(std::move(text));
  while (answers_.size() > kMaxAnswers) answers_.pop_front();
}

void PageMessages::control(const nlohmann::json& m) {
  if (!feed_.onControl)
    return answer(
        error("controls are for replays (pitwall replay FILE --view); this is a live run"));
  try {
    feed_.onControl(m);
  } catch (const std::exception& e) {
    log::warn("view", std::string("a page's control was refused: ") + e.what());
    answer(error(std::string("control refused: ") + e.what()));
  }
}

// {"type":"seat","seat":N,"player":"name"}: this page takes seat N (0: the first free one).
void PageMessages::seat(const nlohmann::json& m) {
  drive::Seats* seats = feed_.seats();
  if (!seats || seats->count() == 0) return answer(error(kDrivingOff));
  const int count = static_cast<int>(seats->count());
  const nlohmann::json* n = field(m, "seat");
  auto number = n ? whole(n, 0, count) : std::optional<int>(0);
  if (!number)  // (a number is shown; anything else by its type: a deep array is not dumped)
    return answer(
        error("seat " +
              (n->is_number() ? n->dump().substr(0, 40) : std::string("(") + n->type_name() + ")") +
              " is not a seat of this run: give 1.." + std::to_string(count) +
              ", or 0 for the first free one"));
  std::string player;
  if (const nlohmann::json* p = field(m, "player"); p && !p->is_null()) {
    if (!p->is_string()) return answer(error("the player's name must be text"));
    player = p->get_ref<const std::string&>().substr(0, 256);  // the seats keep 24 bytes
  }
  auto taken = seats->claim(holder_, drive::Holder::Phone, *number, player);
  if (!taken) return answer(error(taken.error()));
  answer(nlohmann::json{{"type", "seat"}, {"seat", *taken}}.dump());
}

// {"type":"drive","throttle":x,"lane":-1|0|1}: what the driver asks for, and the sign of life
// that keeps the seat live. Refusals are said, the same one at most once a second.
void PageMessages::drive(const nlohmann::json& m) {
  drive::Seats* seats = feed_.seats();
  if (!seats || seats->count() == 0) return refuseDrive(kDrivingOff);
  const nlohmann::json* t = field(m, "throttle");
  if (!t || !t->is_number())
    return refuseDrive("throttle must be a number from 0 (stop) to 1 (full)");
  const nlohmann::json* l = field(m, "lane");
  auto lane = l && !l->is_null() ? whole(l, -1, 1) : std::optional<int>(0);
  if (!lane) return refuseDrive("lane must be -1 (left), 0 or 1 (right)");
  // (what changed reaches the feed through Seats::asked)
  if (auto done = seats->input(holder_, t->get<double>(), *lane); !done)
    return refuseDrive(done.error());
}

void PageMessages::refuseDrive(const std::string& why) {
  const double t = loop_.seconds();
  std::erase_if(said_, [t](const auto& e) { return t - e.second >= kErrorEvery; });
  if (said_.contains(why) || said_.size() >= kMaxAnswers) return;
  said_.emplace(why, t);
  answer(error(why));
}

void PageMessages::leave() {
  if (drive::Seats* seats = feed_.seats()) seats->release(holder_, "the player left");
}

}  // namespace pitwall::view
