#!/usr/bin/python3
"""A client of the seed's controller (github hofdo/nodejsankisdk), written from what its clients
do: the BFH track editor's mqtt.js, the digital twin's dashboard. It speaks exactly their forms
(no "type" key, host id "host", S/Cars read as a bare array and iterated, a retained S/Cars
skipped) and checks every intent and every status and event topic of seed 000 §4.4 against the
bridge it is pointed at. Used by mqtt_seed_client_test.sh against `pitwall bridge`.

  seed_client.py BROKER_PORT

Prints "ok: …" per check, "FAIL: …" per failure; exit status 0 when every check passed.
"""
import json
import sys
import threading
import time

import paho.mqtt.client as mqtt

PORT = int(sys.argv[1])
HOST = "Anki/Host/host"
failures = 0
lock = threading.Condition()
received = []  # (topic, payload text, retained) in arrival order


def ok(what):
    print("ok: " + what, flush=True)


def fail(what):
    global failures
    failures += 1
    print("FAIL: " + what, flush=True)


def on_message(_client, _userdata, msg):
    with lock:
        received.append((msg.topic, msg.payload.decode("utf-8", "replace"), bool(msg.retain)))
        lock.notify_all()


def wait(what, predicate, seconds=10.0, since=0):
    """Until predicate(messages since index `since`) gives a true value; that value, or None."""
    deadline = time.monotonic() + seconds
    with lock:
        while True:
            value = predicate(received[since:])
            if value:
                return value
            left = deadline - time.monotonic()
            if left <= 0:
                fail(what + " (waited %.0f s)" % seconds)
                return None
            lock.wait(left)


def mark():
    with lock:
        return len(received)


def last(messages, topic, where=lambda j: True):
    """The last payload on `topic` (parsed) that satisfies `where`."""
    for t, p, _ in reversed(messages):
        if t == topic:
            j = json.loads(p)
            if where(j):
                return j
    return None


def publish(topic, payload):
    # as the clients send: JSON.stringify, QoS 0, not retained
    client.publish(topic, json.dumps(payload, separators=(",", ":")), qos=0, retain=False)


client = mqtt.Client(client_id="seed-client-%d" % time.time_ns(), protocol=mqtt.MQTTv311)
client.on_message = on_message
client.connect("127.0.0.1", PORT)
client.loop_start()
for topic in [HOST + "/S/#", HOST + "/E/#", "Anki/Car/+/E/#", "Anki/Car/+/S/#"]:
    client.subscribe(topic, qos=1)

# ---- the host is online (retained) ----
if wait("HostStatus true", lambda m: last(m, HOST + "/S/HostStatus") == {"value": True}):
    ok("S/HostStatus is {\"value\":true}")

# ---- the track editor: connecting true on Anki/Host/host/I, then the live S/Cars ----
start = mark()
publish(HOST + "/I", {"connecting": True})


def live_cars(m):
    for t, p, retained in m:
        if t == HOST + "/S/Cars" and not retained:  # mqtt.js: "if(message.retained) break;"
            cars = json.loads(p)
            if isinstance(cars, list) and len(cars) == 2:
                return cars
    return None


cars = wait("a live S/Cars array with the two cars after connecting", live_cars, since=start) or []
seen = []
for car in cars:  # carsArray.forEach(...)
    seen.append(car)
if len(seen) == 2:
    ok("S/Cars is a bare array the client iterates: " + ", ".join(seen))
else:
    print("cannot go on without the cars", flush=True)
    sys.exit(1)
A, B = seen


def car(c, rest):
    return "Anki/Car/%s/%s" % (c, rest)


def speed_of(m, c):
    j = last(m, car(c, "E/speed"))
    return j["value"] if j else None


# ---- S/Information and S/DiscoveryTime as the dashboards read them ----
for c in seen:
    info = wait("S/Information of " + c, lambda m, c=c: last(m, car(c, "S/Information")))
    if info and all(k in info for k in ("address", "identifier", "model", "modelId", "productId")):
        ok("S/Information of %s has address, identifier, model, modelId, productId" % c)
    elif info:
        fail("S/Information of %s lacks a key: %s" % (c, info))
    if wait("S/DiscoveryTime of " + c, lambda m, c=c: last(m, car(c, "S/DiscoveryTime"))):
        ok("S/DiscoveryTime of " + c)

# ---- drive one car by one: the other stays where it is ----
for c, other in ((A, B), (B, A)):
    start = mark()
    publish(car(c, "I"), {"speed": 600, "acceleration": 1000})  # the track editor's changeSpeed
    if wait(c + " drives at about 600 mm/s",
            lambda m, c=c: (speed_of(m, c) or 0) > 450, since=start):
        ok("{\"speed\":600,\"acceleration\":1000} on Anki/Car/%s/I drives it" % c)
    if c == A:
        with lock:
            other_speed = speed_of(received[start:], other)
        if not other_speed:
            ok("the other car did not move")
        else:
            fail("the other car moved: %s mm/s" % other_speed)

# ---- lanes, with the digital twin's values as strings from a form ----
start = mark()
publish(car(A, "I"), {"lane": -23})  # the track editor's changeLane
publish(car(B, "I"), {"lane": "23"})  # the digital twin's form field


def reached(c, target):
    def check(m):
        j = last(m, car(c, "E/lane/offset/actual"))
        return j is not None and abs(j["value"] - target) < 3
    return check


if wait(A + " reaches lane -23", reached(A, -23), since=start):
    ok("{\"lane\":-23} moves the car to -23 mm")
if wait(B + " reaches lane 23", reached(B, 23), since=start):
    ok("{\"lane\":\"23\"} (a string, as a form gives it) moves the car to 23 mm")

# ---- a U-turn: the car faces the other way, the same lane is then -23 from its point of view
start = mark()
publish(car(A, "I"), {"turn": {"type": 3, "time": 0}})
if wait(A + " turned", reached(A, 23), since=start):
    ok("{\"turn\":{\"type\":3,\"time\":0}} turns the car (its offset changes sign)")

# ---- all at once on Anki/Car/I ----
start = mark()
publish("Anki/Car/I", {"speed": 900, "acceleration": 2000})
if wait("both cars at about 900 mm/s",
        lambda m: all((speed_of(m, c) or 0) > 800 for c in seen), since=start):
    ok("{\"speed\":900,…} on Anki/Car/I drives every car")

# ---- battery, version, ping: the replies where the clients read them ----
for c in seen:
    start = mark()
    publish(car(c, "I"), {"battery": True})
    publish(car(c, "I"), {"version": True})
    publish(car(c, "I"), {"ping": True})
    for topic, key in (("S/BatteryLevel", "value"), ("S/Version", "value"), ("S/PingResp", None)):
        j = wait(topic + " of " + c, lambda m, t=topic: last(m, car(c, t)), since=start)
        if j is not None and (key is None or isinstance(j.get(key), int)):
            ok("%s of %s: %s" % (topic, c, json.dumps(j)))
        elif j is not None:
            fail("%s of %s has no integer %s: %s" % (topic, c, key, j))
    for name in ("BATTERY_LEVEL_RESPONSE", "VERSION_RESPONSE", "PING_RESPONSE"):
        t = car(c, "E/Messages/ANKI_VEHICLE_MSG_V2C_" + name)
        if wait(t, lambda m, t=t: last(m, t), since=start):
            ok(t)

# ---- every event topic of §4.4 the simulator's cars send, and the dashboards' E/Messages ----
EVENTS = ["speed", "last_desired_speed", "track_piece_id", "track_location_id",
          "lane/offset/actual", "lane/desired_lane_change_speed", "ave_follow_line_drift_pixels",
          "had_lane_change_activity", "uphill_counter", "downhill_counter", "left_wheel_dist_cm",
          "right_wheel_dist_cm"]
for c in seen:
    for e in EVENTS:
        j = wait(car(c, "E/" + e), lambda m, e=e: last(m, car(c, "E/" + e)))
        if j is not None and isinstance(j.get("timestamp"), int) and "value" in j:
            ok("E/%s of %s: {timestamp, value}" % (e, c))
        elif j is not None:
            fail("E/%s of %s: %s" % (e, c, j))
    position = wait("E/Messages position update of " + c, lambda m: last(
        m, car(c, "E/Messages/ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE")))
    if position and all(k in position for k in ("speed", "offset", "pieceId", "pieceLocation",
                                                "isReverse")):
        ok("the digital twin's position update of %s: speed %s, offset %s, piece %s" %
           (c, position["speed"], position["offset"], position["pieceId"]))
    transition = wait("E/Messages transition update of " + c, lambda m: last(
        m, car(c, "E/Messages/ANKI_VEHICLE_MSG_V2C_LOCALIZATION_TRANSITION_UPDATE")))
    if transition and "left_wheel_dist_cm" in transition and "right_wheel_dist_cm" in transition:
        ok("the digital twin's transition update of " + c)
    for status in ("S/Speed/Actual", "S/Lane/Actual", "S/Speed/Desired", "S/Lane/Desired",
                   "S/CarStatus"):
        if wait(status + " of " + c, lambda m, s=status: last(m, car(c, s))):
            ok("%s of %s" % (status, c))

# ---- too fast on the inner lane of a curve: a car is thrown off, E/Delocalized ----
start = mark()
publish(car(A, "I"), {"lane": 68})
publish(car(B, "I"), {"lane": 68})
wait("both cars at +68 mm", lambda m: all(reached(c, 68)(m) for c in seen), since=start)
publish("Anki/Car/I", {"speed": 1500, "acceleration": 25000})
thrown = wait("E/Delocalized", lambda m: [t for t, _, _ in m if t.endswith("/E/Delocalized")],
              15, start)
if thrown:
    ok("a car thrown off the road publishes " + thrown[0])
    t = thrown[0].replace("/E/Delocalized", "/E/Messages/ANKI_VEHICLE_MSG_V2C_VEHICLE_DELOCALIZED")
    if wait(t, lambda m: last(m, t), since=start):
        ok(t)
start = mark()
publish("Anki/Car/I", {"speed": 0, "acceleration": 25000})
if wait("every car told to stop", lambda m: all(
        (last(m, car(c, "S/Speed/Desired")) or {}).get("value") == 0 for c in seen), since=start):
    ok("{\"speed\":0} on Anki/Car/I stops every car (S/Speed/Desired 0)")

# ---- the host's other intents ----
start = mark()
publish(HOST + "/I", {"cars": True})
if wait("a live S/Cars after {\"cars\":true}", live_cars, since=start):
    ok("{\"cars\":true} publishes S/Cars again")
start = mark()
publish(HOST + "/I", {"car_status": True})
if wait("S/Information of both cars after {\"car_status\":true}",
        lambda m: all(last(m, car(c, "S/Information")) for c in seen), since=start):
    ok("{\"car_status\":true} publishes every car's S/Information again")

# ---- disconnect all, connect again: the host events ----
start = mark()
publish(HOST + "/I", {"connecting": False})
gone = wait("E/CarDisconnected for both cars", lambda m: sorted(
    json.loads(p)["Car"] for t, p, _ in m if t == HOST + "/E/CarDisconnected") == sorted(seen),
    since=start)
if gone:
    ok("{\"connecting\":false} disconnects every car: E/CarDisconnected for both")
if wait("S/Cars empty", lambda m: any(t == HOST + "/S/Cars" and json.loads(p) in ([], {})
                                      for t, p, _ in m), since=start):
    ok("S/Cars lists no car")
start = mark()
publish(HOST + "/I", {"connecting": True})
for event in ("E/CarDiscovered", "E/CarConnected"):
    back = wait(event + " for both cars", lambda m, e=event: sorted(
        json.loads(p)["Car"] for t, p, _ in m if t == HOST + "/" + e) == sorted(seen),
        since=start)
    if back:
        ok("{\"connecting\":true} connects them again: %s for both" % event)
if wait("a live S/Cars with both cars again", live_cars, since=start):
    ok("S/Cars lists both again")

# ---- a malformed intent is answered, and drives nothing ----
start = mark()
publish(car(A, "I"), {"speed": 5000})
err = wait("S/IntentError", lambda m: last(m, HOST + "/S/IntentError"), since=start)
if err and "out of range 0..1500" in err["error"]:
    ok("a speed out of range is answered on S/IntentError: " + err["error"])
elif err:
    fail("unexpected S/IntentError: %s" % err)

client.loop_stop()
client.disconnect()
print("%d failure(s)" % failures, flush=True)
sys.exit(1 if failures else 0)
