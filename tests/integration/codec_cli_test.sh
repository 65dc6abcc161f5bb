# pitwall encode / decode as a user types them (issue: exact forms and exit statuses).
source "$(dirname "$0")/lib.sh"

check "sdk-mode on" "03 90 01 01" "$($PITWALL encode anki sdk-mode on)"
check "set-speed" "06 24 e8 03 a8 61 00" "$($PITWALL encode anki set-speed 1000 25000)"
check "change-lane" "0b 25 e8 03 10 27 00 00 a0 41 00 00" "$($PITWALL encode anki change-lane 1000 10000 20)"
check "set-offset negative" "05 2c 00 00 bc c1" "$($PITWALL encode anki set-offset -23.5)"
check "turn uturn" "03 32 03 00" "$($PITWALL encode anki turn uturn)"
check "ping" "01 16" "$($PITWALL encode anki ping)"
check "version" "01 18" "$($PITWALL encode anki version)"
check "battery" "01 1a" "$($PITWALL encode anki battery)"
check "disconnect" "01 0d" "$($PITWALL encode anki disconnect)"
check "cancel-lane-change" "01 26" "$($PITWALL encode anki cancel-lane-change)"
check "lights" "02 1d 44" "$($PITWALL encode anki lights 0x44)"
pattern=$($PITWALL encode anki lights-pattern 0 3 0 14 5)
check "lights-pattern size byte" "11 33 01 00 03 00 0e 05" "${pattern:0:23}"
contains "config" "03 45" "$($PITWALL encode anki config 0 vinyl)"

err=$($PITWALL encode anki set-speed 2000 2>&1 >/dev/null); rc=$?
check "out-of-range exit status" 2 "$rc"
contains "out-of-range names the range" "0..1500" "$err"
err=$($PITWALL encode anki change-lane 300 3000 75 2>&1 >/dev/null); rc=$?
check "offset beyond 70 mm exit status" 2 "$rc"
contains "offset beyond 70 mm names the range" "offset 75 mm is out of range -70..70 mm" "$err"
check "offset 70 mm is taken" "05 2c 00 00 8c 42" "$($PITWALL encode anki set-offset 70)"
err=$($PITWALL encode anki warp 9 2>&1 >/dev/null); rc=$?
check "unknown command exit status" 2 "$rc"
contains "unknown command lists the known ones" "set-speed" "$err"

out=$($PITWALL decode anki "01 17"); rc=$?
check "decode exit status" 0 "$rc"
contains "decode names the message" '"name":"ping-response"' "$out"
out=$($PITWALL decode anki 10 27 05 11 00 00 b8 41 58 02 00 00 00 00 00 00 00)
contains "decode position piece" '"piece_id":17' "$out"
contains "decode position speed" '"speed_mm_s":600' "$out"
contains "decode position offset" '"offset_mm":23.0' "$out"
out=$($PITWALL decode anki 03 ee 01 02)
contains "unknown id decodes" '"name":"unknown"' "$out"
# A frame longer than its layout is read by it, the extra bytes shown (anki-overdrive.md).
out=$($PITWALL decode anki 11 27 05 11 00 00 b8 41 58 02 00 00 00 00 00 00 00 aa); rc=$?
check "longer frame exit status" 0 "$rc"
contains "longer frame read by its layout" '"speed_mm_s":600' "$out"
contains "longer frame shows its extra bytes" '"extra_bytes":"aa"' "$out"
# py-drivesdk's set speed without its last byte: what a car reads.
out=$($PITWALL decode anki 05 24 f4 01 f4 01)
contains "short set-speed decodes" '"name":"set-speed"' "$out"
contains "short set-speed speed" '"speed_mm_s":500' "$out"
contains "short set-speed respect limit" '"respect_limit":false' "$out"

err=$($PITWALL decode anki 05 27 01 2>&1 >/dev/null); rc=$?
check "malformed exit status" 2 "$rc"
contains "malformed names the id" "0x27" "$err"
err=$($PITWALL decode anki "zz" 2>&1 >/dev/null); rc=$?
check "bad hex exit status" 2 "$rc"
err=$($PITWALL decode mqtt "01 17" 2>&1 >/dev/null); rc=$?
check "unknown protocol exit status" 2 "$rc"
contains "unknown protocol names the known ones" "anki" "$err"
finish
