#pragma once
// Messages as JSON objects: {"name": "position-update", "piece_id": 33, "offset_mm": -23.5, …}.
// Field names carry their unit (_mm, _mm_s, _mm_s2, _cm, _us). Used by `pitwall decode` and by
// `--record` files.
#include <nlohmann/json.hpp>

#include "engine/protocol/anki/codec.hpp"

namespace pitwall::anki {

nlohmann::json toJson(const Message& message);

}  // namespace pitwall::anki
