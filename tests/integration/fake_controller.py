#!/usr/bin/python3
"""The seed's Node controller (github hofdo/nodejsankisdk: host.js, CmdHandler.js,
ReturnMsgHandler.js) as far as MQTT sees it, with one made-up car instead of Bluetooth: it
publishes only what the controller publishes, on its topics and in its forms (no E/frame,
S/Cars a bare array or {}, the controller's E/Messages/ANKI_VEHICLE_MSG_V2C_… payloads, its
"timestamp": Date.now bug that JSON.stringify drops), and executes only the intents the
controller takes (the key names the command; anything else is ignored without an answer).

  fake_controller.py BROKER_PORT CAR_ID

Prints "intent TOPIC PAYLOAD" for every intent it receives and "ready" once subscribed.
Used by mqtt_seed_remote_test.sh to drive `pitwall run --mqtt` against it.
"""
import json
import math
import sys
import threading
import time

import paho.mqtt.client as mqtt

PORT = int(sys.argv[1])
CAR = sys.argv[2]
HOST = "Anki/Host/host"
PIECES = [33, 18, 23, 39, 17, 20, 34]  # the oval's piece ids in driving order
PIECE_MM = 560.0


class Car:
    def __init__(self):
        self.connected = False
        self.speed = 0.0
        self.target = 0.0
        self.accel = 1000.0
        self.offset = -68.0
        self.target_offset = -68.0
        self.travelled = 0.0
        self.last_location = -1
        self.lock = threading.Lock()


car = Car()


def dump(payload):
    return json.dumps(payload, separators=(",", ":"))


def publish(topic, payload, retain=False):
    client.publish(topic, dump(payload), qos=1 if retain else 0, retain=retain)


def now():
    return int(time.time() * 1000)


def on_connect(c, _userdata, _flags, _rc):
    publish(HOST + "/S/HostStatus", {"value": True}, retain=True)
    client.publish(HOST + "/S/Cars", dump({}), qos=1, retain=True)
    c.subscribe(HOST + "/I/#")
    c.subscribe("Anki/Car/+/I/#")
    c.subscribe("Anki/Car/I")


def on_subscribe(_c, _userdata, mid, _qos):
    if mid == 3:
        print("ready", flush=True)


def discover_and_connect():
    # noble's discover: the events and the Information (manufacturer data read as the controller
    # reads it, in the wrong byte order)
    publish(HOST + "/E/CarDiscovered", {"timestamp": now(), "Car": CAR})
    publish("Anki/Car/%s/S/DiscoveryTime" % CAR, {"timestamp": now()}, retain=True)
    publish("Anki/Car/%s/S/Information" % CAR,
            {"address": "d2:05:ef:fe:02:cb", "identifier": 2018915346, "model": "Skull",
             "modelId": 9, "productId": 61374}, retain=True)
    client.publish(HOST + "/S/Cars", dump([CAR]), qos=1, retain=True)
    with car.lock:
        car.connected = True
    publish(HOST + "/E/CarConnected", {"timestamp": now(), "Car": CAR})


def disconnect():
    with car.lock:
        car.connected = False
        car.speed = car.target = 0
    publish("Anki/Car/%s/S/Information" % CAR,
            {"address": "", "identifier": "", "model": "", "modelId": "", "productId": ""},
            retain=True)
    publish(HOST + "/E/CarDisconnected", {"timestamp": now(), "Car": CAR})
    client.publish(HOST + "/S/Cars", dump({}), qos=1, retain=True)


def reply(name, message_id, status_topic, value):
    if status_topic:
        body = {"timestamp": now()}  # Date.now without () is dropped by JSON.stringify
        if value is not None:
            body = {"value": value}
        publish("Anki/Car/%s/%s" % (CAR, status_topic), body, retain=True)
    event = {"message_id": message_id}
    if value is not None:
        event["value"] = value
    publish("Anki/Car/%s/E/Messages/ANKI_VEHICLE_MSG_V2C_%s" % (CAR, name), event)


def command(msg):
    keys = list(msg.keys())
    if not keys:
        return
    first = keys[0]  # CmdHandler: the key names the command
    with car.lock:
        if first in ("speed", "acceleration"):
            car.target = float(msg["speed"])
            car.accel = float(msg.get("acceleration", 1000))
        elif first == "lane":
            car.target_offset = float(msg["offset"])
        elif first == "turn":
            car.target_offset = car.offset = -car.offset
    if first == "battery":
        reply("BATTERY_LEVEL_RESPONSE", 27, "S/BatteryLevel", 3950)
    elif first == "version":
        reply("VERSION_RESPONSE", 25, "S/Version", 0x2b6e)
    elif first == "ping":
        reply("PING_RESPONSE", 23, "S/PingResp", None)


def on_message(_c, _userdata, msg):
    text = msg.payload.decode("utf-8", "replace")
    print("intent %s %s" % (msg.topic, text), flush=True)
    try:
        body = json.loads(text)
    except ValueError:
        return  # the controller would throw here and carry on
    if not isinstance(body, dict):
        return
    topic = msg.topic
    if topic.startswith(HOST + "/I"):
        if list(body.keys()) == ["connecting"]:
            (discover_and_connect if body["connecting"] else disconnect)()
        elif list(body.keys()) == ["cars"]:
            client.publish(HOST + "/S/Cars", dump([CAR] if car.connected else []), qos=1,
                           retain=True)
    elif topic == "Anki/Car/I" or topic.startswith("Anki/Car/%s/I" % CAR):
        if car.connected:
            command(body)


def drive():
    """ReturnMsgHandler's publications for the position updates a driving car sends."""
    step = 0.05
    while True:
        time.sleep(step)  # the made-up car's clock: 20 updates a second
        with car.lock:
            if not car.connected:
                continue
            dv = car.accel * step
            car.speed = min(car.target, car.speed + dv) if car.speed < car.target else max(
                car.target, car.speed - dv)
            if abs(car.target_offset - car.offset) > 0.5:
                car.offset += math.copysign(min(15.0, abs(car.target_offset - car.offset)),
                                            car.target_offset - car.offset)
            car.travelled += car.speed * step
            location = int(car.travelled // 150)
            if location == car.last_location and car.speed > 0:
                continue
            car.last_location = location
            piece = PIECES[int(car.travelled // PIECE_MM) % len(PIECES)]
            speed, offset = int(car.speed), car.offset
        flag = 0x47
        publish("Anki/Car/%s/E/Messages/ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE" % CAR,
                {"message_id": 39, "offset": offset, "speed": speed, "flag": flag,
                 "pieceId": piece, "pieceLocation": location % 48, "isReverse": False,
                 "last_des_speed": int(car.target), "last_rec_lane_change_cmd": 0,
                 "last_exe_lane_change_cmd": 0, "last_des_lane_change_speed": 0})
        publish("Anki/Car/%s/S/Lane/Actual" % CAR, {"timestamp": now(), "value": offset}, True)
        publish("Anki/Car/%s/S/Speed/Actual" % CAR, {"timestamp": now(), "value": speed}, True)
        for name, value in (("lane/offset/actual", offset), ("speed", speed),
                            ("track_piece_id", piece), ("track_location_id", location % 48)):
            publish("Anki/Car/%s/E/%s" % (CAR, name), {"timestamp": now(), "value": value})
        if speed == 0:
            time.sleep(0.5)  # a car standing still reports seldom


client = mqtt.Client(client_id="host-fake-controller", protocol=mqtt.MQTTv31)
client.will_set(HOST + "/S/HostStatus", dump({"value": False}), qos=1, retain=True)
client.on_connect = on_connect
client.on_subscribe = on_subscribe
client.on_message = on_message
client.connect("127.0.0.1", PORT)
threading.Thread(target=drive, daemon=True).start()
client.loop_forever()
