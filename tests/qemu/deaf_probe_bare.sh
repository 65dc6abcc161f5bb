# deaf_probe.sh with no pitwall code on either side (PITWALL_QEMU_CENTRAL=
# script:tests/qemu/deaf_probe_bare.sh): once `pitwall emulate-car` advertises it is stopped
# (SIGTERM: it unregisters, status 0 as guest.sh expects), hci0 advertises through BlueZ's own
# btmgmt (add-adv) instead, and hci1 listens with btmgmt as in deaf_probe.sh.
advertising() { btmgmt --index 0 advinfo 2>&1 | grep -Eq 'Instances list with [1-9]'; }
until_ok 30 advertising || say "[probe] emulate-car never advertised"
kill -TERM "$CAR_PID"
until_ok 10 bash -c "! btmgmt --index 0 advinfo 2>&1 | grep -Eq 'Instances list with [1-9]'" ||
  say "[probe] emulate-car's advertisement did not go"
btmgmt --index 0 add-adv -c -g -d 0509616e6b69 1 >>"$LOGS/radios.log" 2>&1 ||
  say "[probe] btmgmt add-adv failed: $(tail -1 "$LOGS/radios.log")"
say "[probe] hci0 advertises through btmgmt: $(btmgmt --index 0 advinfo 2>&1 | grep -Eo 'Instances list with [0-9]+')"
source "$SRC/tests/qemu/deaf_probe.sh"
