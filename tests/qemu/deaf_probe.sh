# A central for measuring, not testing (PITWALL_QEMU_CENTRAL=script:tests/qemu/deaf_probe.sh):
# with no pitwall code on the central side, does hci1 hear hci0's advertisement? BlueZ's own
# btmgmt runs LE discovery on hci1 PROBES times (default 8), 8 s each, right after the boot, and
# says for each whether the car was heard. Deaf probes here, where no `pitwall scan` ran before,
# show the radios' deafness is the emulation's (tests/qemu/README.md "A failed boot").
probes=${PITWALL_QEMU_PROBES:-8}
heard=0
for k in $(seq 1 "$probes"); do
  timeout 8 stdbuf -oL btmgmt --index 1 find -l >"$LOGS/probe-$k.log" 2>&1
  btmgmt --index 1 stop-find -l >/dev/null 2>&1
  if grep -qi "dev_found: $ADDR0 " "$LOGS/probe-$k.log"; then
    heard=$((heard + 1))
    say "[probe] $k: heard"
  else
    say "[probe] $k: deaf ($(btmgmt --index 0 advinfo 2>&1 | grep -Eo 'Instances list with [0-9]+' || echo 'no advinfo'))"
  fi
done
say "[probe] heard in $heard of $probes probes"
