#!/usr/bin/python3
"""A central that behaves as py-drivesdk does, on Debian's bleak (tests/qemu, central `bleak`).

py-drivesdk (github HHG-TecLap/py-drivesdk) is the Python SDK people drive Anki cars with. This
client does what its Controller and Vehicle do, against `pitwall emulate-car` behind the real
bluetoothd, and fails (exit 1, one line saying what) where the car would not work with it:

1. find the car as py-drivesdk's `_is_anki` does: the local name, encoded as UTF-8, has a state
   byte 0 without the on-charger bit (1 << 6) and decodes as UTF-8 from byte 8; and, stricter than
   py-drivesdk, the advertisement carries the Anki service UUID;
2. connect, write SDK mode on as py-drivesdk does (`03 90 ff 01`: it sends 0xff for "on"), then
   subscribe to the read characteristic (in that order, as py-drivesdk);
3. its set_speed(500): `05 24 f4 01 f4 01`, one byte shorter than drive-sdk's set-speed (no
   "respect road piece speed limit" byte); position updates (0x27, speed u16 at frame offset 8)
   must report about 500 mm/s;
4. its change_lane(Lane4 …) with its defaults (300 mm/s, 300 mm/s², hop 0, tag 0): the position
   updates' offset must reach the lane;
5. ping `01 16` → `01 17`, version `01 18` → 0x19 with the version the name advertised, voltage
   `01 1a` → 0x1b in millivolts;
6. its stop(): set_speed(0, 600), `05 24 00 00 58 02`; the speed the car reports must fall to 0.
   A car at rest sends no position updates, so the speed at rest is read from the speed update
   (0x36: desired, acceleration, actual) the car answers each set-speed with: stop() is sent
   again after each answer until the actual speed is 0.

Every notification is also parsed as py-drivesdk's disassemble_packet does (the size byte must
match the length); any that it would reject fails the run.

    /usr/bin/python3 tests/qemu/central_drivesdk.py --adapter hci1 [--address ADDR]

--address only makes a failure precise (why py-drivesdk would pass over that car); the car is
found by py-drivesdk's rules alone. Waits are on the car's frames; BOUND seconds is how long one
may take before the run fails, never a measure of success.
"""

import argparse
import asyncio
import contextlib
import struct
import sys
import time

from bleak import BleakClient, BleakScanner
from bleak.exc import BleakError

SERVICE_UUID = "be15beef-6186-407e-8381-0bd89c4d8df4"
READ_CHAR_UUID = "be15bee0-6186-407e-8381-0bd89c4d8df4"
WRITE_CHAR_UUID = "be15bee1-6186-407e-8381-0bd89c4d8df4"
ON_CHARGER = 1 << 6  # py-drivesdk: VehicleBattery.ON_CHARGER = 6, a bit of the name's byte 0
LANE4 = {"LEFT_2": -60.0, "LEFT_1": -30.0, "RIGHT_1": 30.0, "RIGHT_2": 60.0}  # py-drivesdk Lane4
SPEED = 500  # mm/s
SPEED_TOLERANCE = 25  # mm/s either side of SPEED
STEADY_UPDATES = 3  # position updates in a row near SPEED
LANE_TOLERANCE = 1.0  # mm
STOP_POLLS = 400  # stop() answers awaited before a car still rolling fails the run
BOUND = 20.0  # seconds one awaited frame may take before the run fails
# The car's first advertisement heard: longer than the emulated radios' deaf spells (30-45 s at a
# time, with no pitwall code on either side: tests/qemu/README.md "A failed boot"), so that one
# spell does not fail the boot (clean-clone run 39 failed both boots on it).
FIND_BOUND = 60.0
CONNECT_ATTEMPTS = 3  # connections tried before the run fails (see connected())

T0 = time.monotonic()


class Failure(Exception):
    pass


def say(text):
    print(f"{time.monotonic() - T0:7.3f} s  {text}", flush=True)


# ---- frames as py-drivesdk builds them (anki/misc/msgs.py, msg_protocol.assemble_packet) ----


def packet(msg_id, payload=b""):
    return bytes([1 + len(payload), msg_id]) + payload


def sdk_mode_pkg():
    return packet(0x90, b"\xff" + (0x01).to_bytes(1, "little"))  # set_sdk_pkg(True, 0x1)


def set_speed_pkg(speed, accel=500):
    # No trailing "respect road piece speed limit" byte: one byte shorter than drive-sdk's.
    return packet(
        0x24, speed.to_bytes(2, "little", signed=True) + accel.to_bytes(2, "little", signed=True)
    )


def change_lane_pkg(offset, h_speed=300, h_accel=300, hop=0, tag=0):
    return packet(0x25, struct.pack("<HHfBB", h_speed, h_accel, offset, hop, tag))


def stop_pkg():
    return set_speed_pkg(0, 600)  # Vehicle.stop(): set_speed(0, 600)


# The bytes the issue measured py-drivesdk sending: a drift here would test something else.
assert set_speed_pkg(500) == bytes.fromhex("05 24 f4 01 f4 01")
assert stop_pkg() == bytes.fromhex("05 24 00 00 58 02")
assert sdk_mode_pkg() == bytes.fromhex("03 90 ff 01")
assert change_lane_pkg(30.0) == bytes.fromhex("0b 25 2c 01 2c 01 00 00 f0 41 00 00")


# ---- how py-drivesdk reads a car's name (anki/control/vehicle.py, controller.py) ----


def interpret_local_name(name):
    """(state byte, version, user name) as py-drivesdk's interpret_local_name; ValueError when
    py-drivesdk could not read it (then it is not a car to py-drivesdk)."""
    if name is None or len(name) < 1:
        raise ValueError("no local name")
    raw = name.encode("utf-8")
    return raw[0], int.from_bytes(raw[1:3], "little", signed=False), raw[8:].decode("utf-8")


def skip_reason(name):
    """Why py-drivesdk's Controller passes over a car with this local name; None if it takes it."""
    try:
        state, _, _ = interpret_local_name(name)
    except ValueError as e:  # UnicodeDecodeError is a ValueError, as in py-drivesdk
        return f"its local name {name!r} cannot be read ({e})"
    if state & ON_CHARGER:
        return f"byte 0 of its local name {name!r} is 0x{state:02x}: the on-charger bit 0x40 is set"
    return None


# ---- the car over bleak ----


class Car:
    def __init__(self, client, write_char):
        self.client = client
        self.write_char = write_char
        self.waiters = []  # [predicate(id, payload) -> result or None, future]
        self.malformed = []
        self.positions = []  # (speed, offset) of every position update
        self.frames = 0

    def on_notify(self, _char, data):
        frame = bytes(data)
        # py-drivesdk's disassemble_packet raises MalformedPacketWarning on these.
        if len(frame) < 2 or frame[0] != len(frame) - 1 or len(frame) - 2 > 18:
            self.malformed.append(frame.hex(" "))
            return
        self.frames += 1
        msg_id, payload = frame[1], frame[2:]
        if msg_id == 0x27:
            if len(payload) < 9:  # disassemble_track_update: struct.unpack_from("<BBfHB")
                self.malformed.append(frame.hex(" "))
                return
            _, _, offset, speed, _ = struct.unpack_from("<BBfHB", payload)
            self.positions.append((speed, offset))
        for waiter in list(self.waiters):
            predicate, future = waiter
            if future.done():
                continue
            try:
                result = predicate(msg_id, payload)
            except Exception as e:  # a predicate's Failure ends the wait with it
                future.set_exception(e)
                continue
            if result is not None:
                future.set_result(result)

    async def request(self, frame, what, predicate):
        """Writes `frame` as py-drivesdk does (write without response) and waits for the first
        notification `predicate` gives a result for; registered before the write."""
        future = asyncio.get_running_loop().create_future()
        waiter = [predicate, future]
        self.waiters.append(waiter)
        try:
            if frame is not None:
                await self.client.write_gatt_char(self.write_char, frame)
            return await asyncio.wait_for(future, BOUND)
        except asyncio.TimeoutError:
            last = self.positions[-1] if self.positions else None
            raise Failure(
                f"no {what} within {BOUND:.0f} s ({self.frames} frames so far, last position "
                f"update (speed, offset): {last})"
            ) from None
        finally:
            self.waiters.remove(waiter)


async def forget(adapter, address):
    """BlueZ keeps a device that an earlier scan found (`pitwall scan`, just before), and bleak
    reports only devices added or changed while it scans: a cached car whose properties do not
    change (btvirt's RSSI does not move) was never reported, now and then. py-drivesdk starts on
    a machine that has not just scanned; so does this client: the car is forgotten first."""
    from dbus_fast import BusType, Message, MessageType
    from dbus_fast.aio import MessageBus

    bus = await MessageBus(bus_type=BusType.SYSTEM).connect()
    try:
        device = f"/org/bluez/{adapter}/dev_" + address.upper().replace(":", "_")
        reply = await bus.call(
            Message(destination="org.bluez", path=f"/org/bluez/{adapter}",
                    interface="org.bluez.Adapter1", member="RemoveDevice", signature="o",
                    body=[device]))
        if reply.message_type == MessageType.ERROR and reply.error_name != "org.bluez.Error.DoesNotExist":
            say(f"could not forget {address} on {adapter}: {reply.error_name} {reply.body}")
    finally:
        bus.disconnect()


async def find_car(adapter, address):
    """The first advertiser py-drivesdk would take for a car that also advertises the Anki service;
    fails at once when `address` advertises a name py-drivesdk would pass over."""
    if address:
        await forget(adapter, address)
    loop = asyncio.get_running_loop()
    found = loop.create_future()

    def detected(device, adv):
        if found.done():
            return
        reason = skip_reason(adv.local_name)
        anki = SERVICE_UUID in [u.lower() for u in adv.service_uuids]
        if reason is None and anki:
            found.set_result((device, adv))
        elif address and device.address.upper() == address.upper() and adv.local_name is not None:
            if reason is not None:
                found.set_exception(
                    Failure(f"py-drivesdk would pass over {device.address}: {reason}")
                )

    async with BleakScanner(detection_callback=detected, adapter=adapter):
        try:
            return await asyncio.wait_for(found, FIND_BOUND)
        except asyncio.TimeoutError:
            raise Failure(f"no car py-drivesdk takes advertised within {FIND_BOUND:.0f} s") from None


@contextlib.asynccontextmanager
async def connected(device):
    """A connection to `device`, tried up to CONNECT_ATTEMPTS times, as BlueZ applications do
    (Home Assistant's bleak-retry-connector, for one): a BlueZ link can drop while it is being
    set up, before the peripheral's GATT server sees it. Under btvirt this happened once in
    many runs ("failed to discover services, device disconnected", and the car logged no
    central). Each failed attempt is said; only the last one fails the run."""
    for attempt in range(1, CONNECT_ATTEMPTS + 1):
        client = BleakClient(device)
        try:
            await client.connect()
            break
        except (BleakError, asyncio.TimeoutError) as e:
            if attempt == CONNECT_ATTEMPTS:
                raise Failure(f"no connection in {CONNECT_ATTEMPTS} attempts; the last: {e!r}")
            say(f"connection attempt {attempt} failed ({e!r}); trying again")
    try:
        yield client
    finally:
        await client.disconnect()


async def drive(adapter, address):
    device, adv = await find_car(adapter, address)
    state, version, user_name = interpret_local_name(adv.local_name)
    say(
        f"found {device.address}: local name {adv.local_name!r} → state 0x{state:02x}, version "
        f"0x{version:04x}, name {user_name!r}; service {SERVICE_UUID}"
    )
    if user_name != "pitwall":
        raise Failure(f"the user name read as py-drivesdk does is {user_name!r}, not 'pitwall'")

    async with connected(device) as client:
        service = client.services.get_service(SERVICE_UUID)
        if service is None:
            raise Failure("the car has no Anki service")
        read = service.get_characteristic(READ_CHAR_UUID)
        write = service.get_characteristic(WRITE_CHAR_UUID)
        if read is None or write is None:
            raise Failure("the Anki service lacks its read or write characteristic")
        car = Car(client, write)
        # py-drivesdk's Vehicle.connect: SDK mode first, then the subscription.
        await client.write_gatt_char(write, sdk_mode_pkg())
        await client.start_notify(read, car.on_notify)
        say("connected; SDK mode on (03 90 ff 01), then subscribed")

        # set_speed(500), the short form: STEADY_UPDATES position updates in a row near it.
        steady = [0]

        def near_speed(msg_id, payload):
            if msg_id != 0x27:
                return None
            speed = struct.unpack_from("<H", payload, 6)[0]  # frame offset 8
            steady[0] = steady[0] + 1 if abs(speed - SPEED) <= SPEED_TOLERANCE else 0
            return speed if steady[0] >= STEADY_UPDATES else None

        speed = await car.request(
            set_speed_pkg(SPEED), f"{STEADY_UPDATES} position updates near {SPEED} mm/s", near_speed
        )
        say(f"set_speed({SPEED}) {set_speed_pkg(SPEED).hex(' ')}: positions say {speed} mm/s")

        # change_lane(Lane4 …): the lane next to the one the car is in.
        offset = car.positions[-1][1]
        names = sorted(LANE4, key=LANE4.get)
        here = min(names, key=lambda n: abs(offset - LANE4[n]))
        i = names.index(here)
        target = names[i + 1] if i + 1 < len(names) else names[i - 1]

        def in_lane(msg_id, payload):
            if msg_id != 0x27:
                return None
            reported = struct.unpack_from("<f", payload, 2)[0]
            return reported if abs(reported - LANE4[target]) <= LANE_TOLERANCE else None

        reached = await car.request(
            change_lane_pkg(LANE4[target]), f"position update in lane {target}", in_lane
        )
        if min(names, key=lambda n: abs(reached - LANE4[n])) != target:
            raise Failure(f"offset {reached:.1f} mm is not py-drivesdk's lane {target}")
        say(f"change_lane(Lane4.{target}) from {here} ({offset:.1f} mm): the car at {reached:.1f} mm")

        # ping, version, voltage.
        def u16_of(wanted):
            return lambda i, p: struct.unpack_from("<H", p)[0] if i == wanted and p[1:] else None

        await car.request(packet(0x16), "ping response 01 17", lambda i, p: i == 0x17 or None)
        car_version = await car.request(packet(0x18), "version response (0x19)", u16_of(0x19))
        if car_version != version:
            raise Failure(f"the car answers version 0x{car_version:04x}, its name 0x{version:04x}")
        mv = await car.request(packet(0x1A), "battery response (0x1b)", u16_of(0x1B))
        if not 3000 <= mv <= 4500:
            raise Failure(f"the battery response says {mv} mV: no LiPo cell's voltage")
        say(f"ping 01 16 → 01 17; version 01 18 → 0x{car_version:04x}; battery 01 1a → {mv} mV")

        # stop(): set_speed(0, 600), again after each answer until the car is at rest.
        def speed_update(msg_id, payload):
            if msg_id != 0x36 or len(payload) < 6:
                return None
            return struct.unpack_from("<hhh", payload)  # desired, acceleration, actual

        before = len(car.positions)
        for poll in range(1, STOP_POLLS + 1):
            desired, accel, actual = await car.request(
                stop_pkg(), "speed update (0x36) after stop()", speed_update
            )
            if desired != 0:
                raise Failure(f"after stop() the car's speed update says desired {desired} mm/s")
            if poll == 1:
                say(f"stop() {stop_pkg().hex(' ')}: the car answers desired 0, at {actual} mm/s")
            if actual == 0:
                break
        else:
            raise Failure(f"still {actual} mm/s after {STOP_POLLS} stop() answers")
        braking = [s for s, _ in car.positions[before:]]
        if any(later > earlier for earlier, later in zip(braking, braking[1:])):
            raise Failure(f"the speed rose while stopping: {braking}")
        say(f"at rest after {poll} stop() answers; position updates while braking: {braking}")

        if car.malformed:
            bad = car.malformed
            raise Failure(f"py-drivesdk would reject {len(bad)} notifications: {bad[:5]}")
        say(f"{car.frames} notifications, all as py-drivesdk parses them")
        # Vehicle.disconnect(): the client disconnects (leaving the `async with`), nothing else.


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--adapter", default="hci1", help="the controller to scan and connect with")
    parser.add_argument("--address", help="the car's address, to say why py-drivesdk would skip it")
    args = parser.parse_args()
    try:
        asyncio.run(drive(args.adapter, args.address))
    except Failure as e:
        say(f"FAIL: {e}")
        return 1
    say("passed: found, driven and stopped as py-drivesdk does")
    return 0


if __name__ == "__main__":
    sys.exit(main())
