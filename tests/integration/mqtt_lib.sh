# For the MQTT integration tests: a private mosquitto on a free loopback port in $TMP (never a
# system broker, never a fixed port), the mosquitto_sub / mosquitto_pub clients pointed at it, and
# background processes (bridges, subscribers, runs) killed at exit. Debian packages: mosquitto,
# mosquitto-clients, openssl.
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
BROKER_PID=""
BROKER_DIR="$TMP/broker"
MQTT_PORT=""
MQTT_URL=""
# extra arguments for mosquitto_sub / mosquitto_pub (TLS, credentials), set by the test
MQTT_CLIENT_ARGS=()
PIDS=()

cleanup_mqtt() {
  local p
  exec 2>/dev/null  # no "Killed" job notices
  for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null; done
  [ -n "$BROKER_PID" ] && kill -9 "$BROKER_PID" 2>/dev/null
  wait 2>/dev/null
  rm -rf "$TMP"
}
trap cleanup_mqtt EXIT

for tool in mosquitto mosquitto_sub mosquitto_pub mosquitto_passwd; do
  command -v "$tool" >/dev/null || [ -x "/usr/sbin/$tool" ] ||
    { echo "FAIL: $tool is missing (Debian packages mosquitto, mosquitto-clients)"; exit 1; }
done
MOSQUITTO=$(command -v mosquitto || echo /usr/sbin/mosquitto)

# free_port: a loopback port nobody listens on (the kernel's pick for port 0).
free_port() {
  python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

# broker_config [anonymous | password USER PASS] [tls CERT KEY CA]: writes the broker's config
# for a new free port; sets MQTT_PORT and MQTT_URL (mqtt:// or mqtts://127.0.0.1:PORT).
broker_config() {
  mkdir -p "$BROKER_DIR"
  MQTT_PORT=$(free_port)
  local conf="$BROKER_DIR/mosquitto.conf" scheme=mqtt
  {
    echo "listener $MQTT_PORT 127.0.0.1"
    echo "persistence false"
    echo "set_tcp_nodelay true"  # as docs/mqtt.md recommends
    echo "user root"  # a container runs as root: stay root, keep reading the temp dir
    # the default types, and every SUBSCRIBE ("CLIENT-ID QOS FILTER"), for the tests to read
    printf 'log_type %s\n' error warning notice information subscribe
  } >"$conf"
  while [ $# -gt 0 ]; do
    case $1 in
      anonymous) echo "allow_anonymous true" >>"$conf"; shift ;;
      password)
        mosquitto_passwd -c -b "$BROKER_DIR/passwd" "$2" "$3" >/dev/null 2>&1 ||
          { echo "FAIL: mosquitto_passwd failed"; exit 1; }
        printf 'allow_anonymous false\npassword_file %s\n' "$BROKER_DIR/passwd" >>"$conf"
        shift 3 ;;
      tls) printf 'certfile %s\nkeyfile %s\ncafile %s\n' "$2" "$3" "$4" >>"$conf"; scheme=mqtts; shift 4 ;;
      *) echo "FAIL: broker_config: unknown argument $1"; exit 1 ;;
    esac
  done
  MQTT_URL="$scheme://127.0.0.1:$MQTT_PORT"
}

# listening PORT: true when something accepts TCP connections on 127.0.0.1:PORT.
listening() {
  (exec 9<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null
}

# start_broker: starts mosquitto with the config (again on the same port after stop_broker) and
# returns once it accepts connections; its log is $BROKER_DIR/mosquitto.log.
start_broker() {
  "$MOSQUITTO" -c "$BROKER_DIR/mosquitto.conf" >>"$BROKER_DIR/mosquitto.log" 2>&1 &
  BROKER_PID=$!
  local deadline=$((SECONDS + 5))
  until listening "$MQTT_PORT"; do
    if ! kill -0 "$BROKER_PID" 2>/dev/null; then
      echo "FAIL: mosquitto exited at start: $(cat "$BROKER_DIR/mosquitto.log")"
      BROKER_PID=""
      exit 1
    fi
    if [ $SECONDS -ge $deadline ]; then
      echo "FAIL: mosquitto did not listen on port $MQTT_PORT: $(cat "$BROKER_DIR/mosquitto.log")"
      exit 1
    fi
    sleep 0.02
  done
}

# stop_broker: ends mosquitto (SIGTERM) and waits for it; the port is free again afterwards.
stop_broker() {
  [ -n "$BROKER_PID" ] || return 0
  kill -TERM "$BROKER_PID" 2>/dev/null
  wait "$BROKER_PID" 2>/dev/null
  BROKER_PID=""
}

# spawn NAME COMMAND…: COMMAND in the background, stdout in $TMP/NAME.out, stderr in
# $TMP/NAME.err; sets LAST_PID; killed at exit if still running.
spawn() {
  local name=$1
  shift
  "$@" >"$TMP/$name.out" 2>"$TMP/$name.err" &
  LAST_PID=$!
  PIDS+=("$LAST_PID")
}

# pub TOPIC PAYLOAD [mosquitto_pub options…]: one message (QoS 1, so it has reached the broker
# when pub returns).
pub() {
  local topic=$1 payload=$2
  shift 2
  mosquitto_pub -h 127.0.0.1 -p "$MQTT_PORT" "${MQTT_CLIENT_ARGS[@]}" -q 1 -t "$topic" -m "$payload" "$@"
}

# subscribe NAME FILTER…: a mosquitto_sub -v in the background writing "topic payload" lines to
# $TMP/NAME.sub; returns once it is subscribed (a marker of its own came back). Sets SUB_PID.
subscribe() {
  local name=$1 filter args=()
  shift
  for filter in "$@"; do args+=(-t "$filter"); done
  mosquitto_sub -h 127.0.0.1 -p "$MQTT_PORT" "${MQTT_CLIENT_ARGS[@]}" -v -q 1 "${args[@]}" \
    -t "pitwall-test/ready/$name" >"$TMP/$name.sub" 2>"$TMP/$name.sub.err" &
  SUB_PID=$!
  PIDS+=("$SUB_PID")
  local deadline=$((SECONDS + 5))
  until grep -q "^pitwall-test/ready/$name " "$TMP/$name.sub" 2>/dev/null; do
    [ $SECONDS -ge $deadline ] && { fail "subscriber $name never subscribed: $(cat "$TMP/$name.sub.err")"; return 1; }
    pub "pitwall-test/ready/$name" up
    sleep 0.05
  done
}

# retained FILTER: the retained messages under FILTER now, as "topic payload" lines on stdout
# (a late subscriber: mosquitto_sub ends at the first live message or after 1 s).
retained() {
  timeout 10 mosquitto_sub -h 127.0.0.1 -p "$MQTT_PORT" "${MQTT_CLIENT_ARGS[@]}" -v -q 1 \
    --retained-only -W 1 -t "$1" 2>/dev/null
  return 0
}

# last_value FILE TOPIC: the payload of the last "TOPIC payload" line of a subscriber's FILE.
last_value() {
  grep -F "$2 " "$1" | tail -1 | cut -d' ' -f2-
}

# make_ca DIR NAME: a throwaway CA, DIR/NAME.crt and DIR/NAME.key (EC keys: fast).
make_ca() {
  mkdir -p "$1"
  openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -keyout "$1/$2.key" \
    -out "$1/$2.crt" -days 1 -subj "/CN=$2" >>"$1/openssl.log" 2>&1 ||
    { echo "FAIL: openssl could not make a CA: $(cat "$1/openssl.log")"; exit 1; }
}

# make_server_cert DIR CA: DIR/server.crt and DIR/server.key for 127.0.0.1, signed by DIR/CA.crt.
make_server_cert() {
  local d=$1 ca=$2
  printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\n' >"$d/ext.cnf"
  { openssl req -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -keyout "$d/server.key" \
      -out "$d/server.csr" -subj /CN=127.0.0.1 &&
    openssl x509 -req -in "$d/server.csr" -CA "$d/$ca.crt" -CAkey "$d/$ca.key" -CAcreateserial \
      -out "$d/server.crt" -days 1 -extfile "$d/ext.cnf"; } >>"$d/openssl.log" 2>&1 ||
    { echo "FAIL: openssl could not make the server certificate: $(cat "$d/openssl.log")"; exit 1; }
}
