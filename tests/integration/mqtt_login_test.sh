# Logging in to a broker as a user does it (docs/mqtt.md "Options"): a private mosquitto with TLS
# (a throwaway CA, mqtts://127.0.0.1:PORT) and a password file. The bridge and a run with remote
# cars connect with the right password from --mqtt-password-file and from $PITWALL_MQTT_PASSWORD;
# a wrong password, a missing user and --mqtt-ca without TLS end with status 2 saying why; a CA
# that did not sign the broker's certificate is named in the log.
source "$(dirname "$0")/mqtt_lib.sh"
command -v openssl >/dev/null || { echo "FAIL: the openssl command is missing (Debian package: openssl)"; exit 1; }

T="$TMP/tls"
make_ca "$T" testca
make_server_cert "$T" testca
make_ca "$T" other  # signed nothing of the broker's
broker_config password pitwall 's3cret pass' tls "$T/server.crt" "$T/server.key" "$T/testca.crt"
start_broker
check "the broker URL is mqtts://" "mqtts://127.0.0.1:$MQTT_PORT" "$MQTT_URL"
MQTT_CLIENT_ARGS=(--cafile "$T/testca.crt" -u pitwall -P 's3cret pass')
subscribe all 'Anki/#'
ALL="$TMP/all.sub"
printf 's3cret pass\n' >"$TMP/good"
printf 's3cret pass\r\n' >"$TMP/good-crlf"
printf 'guess\n' >"$TMP/wrong"
LOGIN=(--mqtt "$MQTT_URL" --mqtt-ca "$T/testca.crt" --mqtt-user pitwall)

# ---- the right password from a file (also with a CRLF line end), and from the environment ----
timeout 20 $PITWALL bridge "${LOGIN[@]}" --mqtt-password-file "$TMP/good" --host-id file \
  --cars 1 --duration 1 2>"$TMP/file.err"
check "password file: exit status" 0 "$?"
contains "password file: connected over TLS" "connected to $MQTT_URL" "$(cat "$TMP/file.err")"
grep -q '^Anki/Host/file/S/HostStatus {"value":true}' "$ALL" &&
  echo "ok: password file: the bridge published" || fail "password file: no HostStatus true"

timeout 20 $PITWALL bridge "${LOGIN[@]}" --mqtt-password-file "$TMP/good-crlf" --host-id crlf \
  --cars 1 --duration 1 2>"$TMP/crlf.err"
check "password file with CRLF: exit status" 0 "$?"

PITWALL_MQTT_PASSWORD='s3cret pass' timeout 20 $PITWALL bridge "${LOGIN[@]}" --host-id env \
  --cars 1 --duration 1 2>"$TMP/env.err"
check "PITWALL_MQTT_PASSWORD: exit status" 0 "$?"
grep -q '^Anki/Host/env/S/HostStatus {"value":true}' "$ALL" &&
  echo "ok: PITWALL_MQTT_PASSWORD: the bridge published" || fail "PITWALL_MQTT_PASSWORD: no HostStatus true"

# a run takes the bridged car as a remote car through the same login
spawn bridge $PITWALL bridge "${LOGIN[@]}" --mqtt-password-file "$TMP/good" --host-id remote --cars 1
wait_for "$TMP/bridge.err" "bridging 1 car as host remote" || fail "the bridge did not start: $(cat "$TMP/bridge.err")"
cat >"$TMP/count.lua" <<'LUA'
print("cars: " .. #pitwall.cars())
pitwall.stop()
LUA
out=$(PITWALL_MQTT_PASSWORD='s3cret pass' timeout 20 $PITWALL run "$TMP/count.lua" --cars 0 \
  "${LOGIN[@]}" --remote-cars 1 2>"$TMP/run.err"); rc=$?
check "run with remote cars over TLS: exit status" 0 "$rc"
check "run with remote cars over TLS: the car joined" "cars: 1" "$out"
err=$(timeout 20 $PITWALL run "$TMP/count.lua" --cars 0 "${LOGIN[@]}" --mqtt-password-file "$TMP/wrong" \
  --remote-cars 1 2>&1 >/dev/null); rc=$?
check "run, wrong password: exit status" 2 "$rc"
contains "run, wrong password: the refusal is named" "the broker refused the connection ($MQTT_URL): " "$err"

# ---- refusals: status 2 and the reason ----
err=$(timeout 20 $PITWALL bridge "${LOGIN[@]}" --mqtt-password-file "$TMP/wrong" --cars 1 2>&1); rc=$?
check "wrong password: exit status" 2 "$rc"
contains "wrong password: the refusal is named" "the broker refused the connection: " "$err"
contains "wrong password: mosquitto's reason" "not authori" "$err"
err=$(timeout 20 $PITWALL bridge --mqtt "$MQTT_URL" --mqtt-ca "$T/testca.crt" --cars 1 2>&1); rc=$?
check "no credentials: exit status" 2 "$rc"
contains "no credentials: the refusal is named" "the broker refused the connection: " "$err"
err=$(PITWALL_MQTT_PASSWORD=x timeout 20 $PITWALL bridge --mqtt "$MQTT_URL" --mqtt-ca "$T/testca.crt" \
  --cars 1 2>&1); rc=$?
check "a password without --mqtt-user: exit status" 2 "$rc"
contains "a password without --mqtt-user: says so" "\$PITWALL_MQTT_PASSWORD gives a password without --mqtt-user" "$err"
err=$(timeout 20 $PITWALL bridge --mqtt "$MQTT_URL" --mqtt-ca "$T/testca.crt" \
  --mqtt-password-file "$TMP/good" --cars 1 2>&1); rc=$?
check "a password file without --mqtt-user: exit status" 2 "$rc"
contains "a password file without --mqtt-user: says so" "--mqtt-password-file gives a password without --mqtt-user" "$err"
err=$(timeout 20 $PITWALL bridge --mqtt "mqtt://127.0.0.1:$MQTT_PORT" --mqtt-ca "$T/testca.crt" \
  --mqtt-user pitwall --mqtt-password-file "$TMP/good" --cars 1 2>&1); rc=$?
check "--mqtt-ca with mqtt://: exit status" 2 "$rc"
contains "--mqtt-ca with mqtt://: says so" "--mqtt-ca needs an mqtts:// URL (TLS)" "$err"
err=$(timeout 20 $PITWALL bridge "${LOGIN[@]}" --mqtt-password-file "$TMP/missing" --cars 1 2>&1); rc=$?
check "an unreadable password file: exit status" 2 "$rc"
contains "an unreadable password file: says so" "cannot read a password from $TMP/missing" "$err"

# ---- a CA that did not sign the broker's certificate: the handshake fails, the log says why ----
timeout 20 $PITWALL bridge --mqtt "$MQTT_URL" --mqtt-ca "$T/other.crt" --mqtt-user pitwall \
  --mqtt-password-file "$TMP/good" --host-id wrongca --cars 1 --mqtt-timeout 2 --duration 3 \
  >/dev/null 2>"$TMP/wrongca.err"
rc=$?
contains "wrong CA: the log names the failed verification" "certificate verify failed" "$(cat "$TMP/wrongca.err")"
[ "$rc" -ne 124 ] && echo "ok: wrong CA: the bridge ends (status $rc)" || fail "wrong CA: the bridge hung"
check "wrong CA: nothing was published" "" "$(grep '^Anki/Host/wrongca/' "$ALL")"

finish
