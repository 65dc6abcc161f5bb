#include "engine/sim/world.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "engine/core/interpolate.hpp"
#include "engine/sim/code_layout.hpp"
#include "engine/sim/sim_car.hpp"

namespace pitwall::sim {

namespace {

// Collision rule (docs/simulator.md "Collisions").
constexpr double kCarLengthMm = 90;  // centre to centre, along the track, when touching
constexpr double kOverlapMm = 40;    // lanes closer than this overlap
constexpr double kLookaheadMm = 50;  // beyond any one tick's closing distance (2 × 7.5 mm)
constexpr double kReleaseMm = 5;     // a contact ends once the gap opens by this much

// The most a late tick makes up for at once (World::State::tick).
constexpr Duration kMaxCatchUp = std::chrono::seconds(1);

// Identifiers the world hands out when a spec leaves it 0: recognisable, and stable per index.
constexpr std::uint32_t kIdentifierBase = 0x51A00000;

// Where the location codes lie along a piece (docs/simulator.md "Location codes"): one per
// code section, reported at the section's centre, in every row of the piece's code layout.
PieceInfo describe(const Piece& piece) {
  PieceInfo info;
  info.piece = piece;
  info.centre_mm = piece.length(0);
  CodeGeometry g;
  info.row_pitch_mm = g.row_pitch_mm;
  for (const CodeRow& row : codeLayout(piece, g).rows) {
    PieceInfo::Row r;
    r.reversed = row.reversed;
    for (int k = 0; k < row.sections; ++k) {
      r.code_at.push_back(row.sectionCentre(k) / row.length_mm);
      r.location.push_back(row.locationOf(k));
    }
    info.rows.push_back(std::move(r));
  }
  return info;
}

}  // namespace

struct World::State {
  State(Loop& loop, Track t, std::uint64_t seed)
      : track(std::move(t)), env{loop, track, {}, 0, {}, SensorModel::Real, std::mt19937_64(seed),
                                 {}} {
    if (track.size() == 0) throw std::invalid_argument("a simulated world needs a track");
    std::size_t n = track.size();
    env.pieces.resize(n);
    std::size_t finish = track.finishIndex();
    double at = 0;
    for (std::size_t k = 0; k < n; ++k) {
      std::size_t i = (finish + k) % n;
      env.pieces[i] = describe(track.piece(i));
      env.pieces[i].lap_start_mm = at;
      at += env.pieces[i].centre_mm;
    }
    env.lap_mm = at;
    env.wake = [this] { wake(); };
  }

  ~State() {
    if (timer) env.loop.cancel(timer);
  }

  // Ticks run on a fixed grid (multiples of kTick on the loop clock) and only while some car
  // has something to do, so an idle world leaves the loop free to finish.
  void wake() {
    if (timer || cars.empty()) return;
    schedule((env.loop.now() / kTick + 1) * kTick);
  }

  void schedule(TimePoint at) {
    due = at;
    timer = env.loop.at(at, [this] { tick(); });
  }

  // On the real clock the loop may run a tick late (a script's long callback, a loaded
  // machine): the cars move on by the wall clock, as real cars do, with every tick they missed
  // (at most kMaxCatchUp; a longer stall — a suspended run — is skipped). On a virtual clock a
  // tick is never late: one step each.
  void tick() {
    timer = 0;
    const TimePoint now = env.loop.now();
    const auto missed = now > due ? (now - due) / kTick : 0;
    const auto steps = std::min<std::int64_t>(missed + 1, kMaxCatchUp / kTick);
    const double dt = toSeconds(kTick);
    bool busy = true;
    for (std::int64_t k = 0; k < steps && busy; ++k) {
      for (auto& car : cars) car->plan(dt);
      resolveCollisions();
      for (auto& car : cars) car->commit();
      busy = std::any_of(cars.begin(), cars.end(), [](auto& c) { return c->active(); });
    }
    lateTicks += static_cast<std::uint64_t>(steps - 1);
    if (!busy) return;
    TimePoint next = due + steps * kTick;
    if (next <= now) next = (now / kTick + 1) * kTick;  // past the catch-up's cap: skipped
    schedule(next);
  }

  // Car indices sorted by (lap position, index), and each car's rank in that order. Positions
  // change little from one tick to the next, so the insertion sort is linear in practice.
  void sortByPosition() {
    const std::size_t n = cars.size();
    for (std::size_t i = 0; i < n; ++i) position[i] = cars[i]->lapPosition();
    auto before = [this](std::size_t a, std::size_t b) {
      return position[a] < position[b] || (position[a] == position[b] && a < b);
    };
    for (std::size_t k = 1; k < n; ++k) {
      std::size_t v = order[k], m = k;
      for (; m > 0 && before(v, order[m - 1]); --m) order[m] = order[m - 1];
      order[m] = v;
    }
    for (std::size_t k = 0; k < n; ++k) rank[order[k]] = k;
  }

  // The k-th car after car i in i's driving direction, and the distance to it along the centre
  // line (positions as they were at the start of this tick). Cars at one spot: the one later in
  // the sorted order leads.
  std::pair<std::size_t, double> nextAhead(std::size_t i, std::size_t k) const {
    const std::size_t n = cars.size();
    const int dir = cars[i]->direction();
    std::size_t r = dir > 0 ? (rank[i] + k) % n : (rank[i] + n - k) % n;
    std::size_t j = order[r];
    bool wrapped = dir > 0 ? r < rank[i] : r > rank[i];
    double d = (position[j] - position[i]) * dir;
    if (d < 0 || (d == 0 && wrapped)) d += env.lap_mm;
    return {j, d};
  }

  // A car may not pass through the car ahead of it on an overlapping lane: it is held at one
  // car length and takes that car's speed. Only cars within reach are looked at; passes repeat
  // so a chain of cars settles.
  void resolveCollisions() {
    const std::size_t n = cars.size();
    if (n < 2) return;
    std::fill(holder.begin(), holder.end(), -1);
    sortByPosition();
    for (std::size_t pass = 0; pass < n; ++pass) {
      bool changed = false;
      for (std::size_t i = 0; i < n; ++i) {
        Car& a = *cars[i];
        if (!a.solid() || a.plannedAdvance() <= 0) continue;
        for (std::size_t k = 1; k < n; ++k) {
          auto [j, gap] = nextAhead(i, k);
          if (gap >= kCarLengthMm + kLookaheadMm) break;
          Car& b = *cars[j];
          if (!b.solid() || std::abs(a.trackOffset() - b.trackOffset()) >= kOverlapMm) continue;
          double b_moves = b.plannedAdvance() * (a.direction() == b.direction() ? 1 : -1);
          double allowed = std::max(0.0, gap + b_moves - kCarLengthMm);
          if (allowed < a.plannedAdvance()) {
            a.holdAt(allowed, a.speed());
            holder[i] = static_cast<int>(j);
            changed = true;
          }
        }
      }
      if (!changed) break;
    }
    // Held cars take the speed of the car that holds them (nothing, head-on); repeated so the
    // speed of a chain's front car reaches its back.
    for (std::size_t pass = 0; pass < n; ++pass) {
      bool changed = false;
      for (std::size_t i = 0; i < n; ++i) {
        if (holder[i] < 0) continue;
        Car& a = *cars[i];
        Car& b = *cars[static_cast<std::size_t>(holder[i])];
        double v = a.direction() == b.direction() ? std::min(a.speed(), b.speed()) : 0.0;
        if (v == a.speed()) continue;
        a.holdAt(a.plannedAdvance(), v);
        changed = true;
      }
      if (!changed) break;
    }
    updateContacts();
  }

  // One collision per contact, not per tick: a contact starts when a car is held and lasts
  // while the two stay within a car length (plus kReleaseMm) on overlapping lanes.
  void updateContacts() {
    const std::size_t n = cars.size();
    for (std::size_t i = 0; i < n; ++i) {
      if (holder[i] < 0) continue;
      std::size_t j = static_cast<std::size_t>(holder[i]);
      if (contact[i * n + j]) continue;
      contact[i * n + j] = 1;
      touching.emplace_back(i, j);
      Car& a = *cars[i];
      Car& b = *cars[j];
      bool head_on = a.direction() != b.direction();
      if (head_on && contact[j * n + i]) continue;  // already counted from b's side
      a.collided(true);
      b.collided(head_on);
    }
    for (std::size_t k = 0; k < touching.size();) {
      auto [i, j] = touching[k];
      Car& a = *cars[i];
      Car& b = *cars[j];
      bool apart =
          holder[i] != static_cast<int>(j) &&
          (!a.solid() || !b.solid() || std::abs(a.trackOffset() - b.trackOffset()) >= kOverlapMm ||
           gapAfterMove(i, j) >= kCarLengthMm + kReleaseMm);
      if (!apart) {
        ++k;
        continue;
      }
      contact[i * n + j] = 0;
      touching[k] = touching.back();
      touching.pop_back();
    }
  }

  // Distance from car i to car j, in i's direction, once both have made this tick's move.
  double gapAfterMove(std::size_t i, std::size_t j) const {
    const Car& a = *cars[i];
    const Car& b = *cars[j];
    double d = (position[j] - position[i]) * a.direction();
    if (d < 0) d += env.lap_mm;
    return d - a.plannedAdvance() + b.plannedAdvance() * (a.direction() == b.direction() ? 1 : -1);
  }

  Track track;
  Environment env;
  std::vector<std::unique_ptr<Car>> cars;
  std::vector<double> position;       // per car: centre-line lap position this tick
  std::vector<std::size_t> order;     // car indices by position
  std::vector<std::size_t> rank;      // per car: its place in `order`
  std::vector<int> holder;            // per car: index of the car holding it this tick, or −1
  std::vector<std::uint8_t> contact;  // n × n: car i touches car j ahead of it
  std::vector<std::pair<std::size_t, std::size_t>> touching;  // the pairs set in `contact`
  Loop::TimerId timer = 0;
  TimePoint due{0};             // when the scheduled tick is due
  std::uint64_t lateTicks = 0;  // ticks made up for after the loop ran late
};

World::World(Loop& loop, Track track, std::uint64_t seed)
    : state_(std::make_unique<State>(loop, std::move(track), seed)) {}

World::~World() = default;

const Track& World::track() const {
  return state_->track;
}
std::uint64_t World::lateTicks() const {
  return state_->lateTicks;
}
Loop& World::loop() {
  return state_->env.loop;
}

double GhostLap::distanceAt(double t) const {
  if (points.empty()) return 0;
  return interpolate(
      points, t, [](const Point& p) { return p.t; }, [](const Point& p) { return p.distance; });
}

double GhostLap::offsetAt(double distance, double otherwise) const {
  if (lanes.empty()) return otherwise;
  auto it = std::upper_bound(lanes.begin(), lanes.end(), distance,
                             [](double d, const Lane& l) { return d < l.distance; });
  return it == lanes.begin() ? lanes.front().offset : (it - 1)->offset;
}

SimCar& World::addCar(CarSpec spec) {
  State& s = *state_;
  if (spec.piece_index >= s.track.size())
    throw std::out_of_range("car '" + spec.name + "' starts on piece index " +
                            std::to_string(spec.piece_index) + " but track '" + s.track.name() +
                            "' has only " + std::to_string(s.track.size()) + " pieces");
  std::size_t index = s.cars.size();
  std::uint32_t id =
      spec.identifier ? spec.identifier : kIdentifierBase + static_cast<std::uint32_t>(index + 1);
  s.cars.push_back(std::make_unique<Car>(s.env, std::move(spec), id));
  std::size_t n = s.cars.size();
  s.holder.assign(n, -1);
  s.position.assign(n, 0);
  s.order.push_back(index);
  s.rank.assign(n, 0);
  s.touching.reserve(n * n);  // never grows during a tick
  // Keep the contacts known so far; new rows and columns start apart.
  std::vector<std::uint8_t> contact(n * n, 0);
  for (std::size_t i = 0; i + 1 < n; ++i)
    for (std::size_t j = 0; j + 1 < n; ++j) contact[i * n + j] = s.contact[i * (n - 1) + j];
  s.contact = std::move(contact);
  return *s.cars.back();
}

std::vector<SimCar*> World::cars() {
  std::vector<SimCar*> out;
  for (auto& car : state_->cars) out.push_back(car.get());
  return out;
}

void World::setNoise(Noise noise) {
  noise.drop = std::clamp(noise.drop, 0.0, 1.0);
  noise.late = std::clamp(noise.late, 0.0, 1.0);
  if (noise.late_by < Duration::zero()) noise.late_by = Duration::zero();
  state_->env.noise = noise;
}

const Noise& World::noise() const {
  return state_->env.noise;
}

void World::setSensor(SensorModel model) {
  state_->env.sensor = model;
}

SensorModel World::sensor() const {
  return state_->env.sensor;
}

}  // namespace pitwall::sim
