#!/bin/sh
# End-to-end check of `sedbridge make-log` and `sedbridge decode`:
#   decode_cli_test.sh SEDBRIDGE_BINARY SOURCE_DIR WORK_DIR
set -eu
bin=$1 src=$2 work=$3
mkdir -p "$work"
cd "$work"

fail() { echo "FAIL: $*"; exit 1; }

# 1. A hand-made log with one of each fault: every count is known.
"$bin" decode --profile cyskin_16 "$src/tests/sensors/data/cyskin_faults.log" --csv faults.csv > faults.txt
cat faults.txt
grep -Eq '^  lines +21$' faults.txt || fail "lines"
grep -Eq '^  bad_lines +2$' faults.txt || fail "bad_lines"
grep -Eq '^  scans +4 \(3 complete, 1 partial\)$' faults.txt || fail "scans"
grep -Eq '^  duplicates +1$' faults.txt || fail "duplicates"
grep -Eq '^  reordered +1$' faults.txt || fail "reordered"
grep -Eq '^  wrong_length +1$' faults.txt || fail "wrong_length"
grep -Eq '^  unknown_id +1$' faults.txt || fail "unknown_id"
grep -Eq '^  error_frames +1$' faults.txt || fail "error_frames"
grep -Eq '^  saturated_values +1$' faults.txt || fail "saturated_values"
grep -Eq 'faults.log:10: .*this line is not a frame' faults.txt || fail "bad line 10 reported"
grep -Eq 'faults.log:17: .*6 or 9' faults.txt || fail "bad line 17 reported"
grep -Eq 'bus_off 1' faults.txt || fail "bus-off decoded"
[ "$(wc -l < faults.csv)" -eq 5 ] || fail "csv rows"
head -1 faults.csv | grep -q '^scan,utime,complete,t0_z_Pa,t1_z_Pa' || fail "csv header"

# 1b. A bad line's bytes are not echoed raw: an escape sequence is shown as \x1b.
printf '(1.000000) can0 405#0000\n(1.000100) \033[2Jcan0 x\n' > escape.log
"$bin" decode --profile cyskin_16 escape.log > escape.txt || true
if grep -q "$(printf '\033')" escape.txt; then fail "raw escape byte echoed"; fi
grep -q 'x1b\[2J' escape.txt || fail "escape shown as \\x1b"

# 2. make-log -> decode round trip for every shipped profile.
for profile in uskin_4x4 cyskin_16 barrett_bh8_pad; do
  "$bin" make-log --profile $profile --scene "$src/config/scenes/sensor_sphere_press.yaml" \
      --duration-s 0.5 --seed 1 --out $profile.log --truth-csv $profile.truth.csv > make.txt
  cat make.txt
  "$bin" decode --profile $profile $profile.log --csv $profile.csv > decode.txt
  grep -Eq '^  bad_lines +0$' decode.txt || fail "$profile bad lines"
  grep -Eq '^  unknown_id +0$' decode.txt || fail "$profile unknown ids"
  grep -Eq '^  scans_partial +0$' decode.txt || fail "$profile partial scans"
  [ "$(wc -l < $profile.csv)" -eq "$(wc -l < $profile.truth.csv)" ] || fail "$profile row count"
  [ "$(head -1 $profile.csv)" = "$(head -1 $profile.truth.csv)" ] || fail "$profile header"
done

# 2b. Taxel health: which taxels were masked, why and when (the example press; taxel 5 stuck
# high from the first scan by tools/edit_taxel_log.py).
"$bin" decode --profile uskin_4x4 "$src/config/bridge/example_press.log" > healthy.txt
grep -q '^taxel health: no taxel masked$' healthy.txt || fail "healthy log: taxel health"
python3 "$src/tools/edit_taxel_log.py" "$src/config/bridge/example_press.log" stuck5.log --taxel 5 --mode stuck
"$bin" decode --profile uskin_4x4 stuck5.log > stuck5.txt
cat stuck5.txt
grep -q '^taxel health: 1 masking; masked at the end: 5 stuck high$' stuck5.txt || fail "stuck taxel: taxel health"
grep -Eq '^  taxel 5 stuck high: masked 0\.0[0-9]+ s to the end \([0-9]+ scans\)$' stuck5.txt || fail "stuck taxel: episode"
# The heatmap's CSV says which taxel is masked at the drawn scan (plot_taxels.py crosses it out).
"$bin" decode --profile uskin_4x4 stuck5.log --heatmap-png stuck5.png > /dev/null 2>&1 || true
grep -q '^5,.*,stuck high$' stuck5.png.csv || fail "stuck taxel: heatmap CSV health of taxel 5"
[ "$(grep -c ',healthy$' stuck5.png.csv)" = 15 ] || fail "stuck taxel: heatmap CSV, 15 healthy taxels"

# 3. Same seed, same log.
"$bin" make-log --profile cyskin_16 --scene "$src/config/scenes/sensor_sphere_press.yaml" \
    --duration-s 0.5 --seed 1 --out again.log > /dev/null
cmp -s again.log cyskin_16.log || fail "make-log not deterministic"

# 4. Usage errors exit with 2; --help works.
"$bin" decode --help | grep -q 'usage: sedbridge decode' || fail "decode --help"
"$bin" make-log --help | grep -q 'usage: sedbridge make-log' || fail "make-log --help"
set +e
"$bin" decode --profile cyskin_16 --bogus x.log 2>/dev/null; [ $? -eq 2 ] || fail "unknown option exit status"
"$bin" decode --profile cyskin_16 2>/dev/null; [ $? -eq 2 ] || fail "neither LOG nor --interface"
# 5. Live input: without AF_CAN (or without the interface) a clear error, never a crash.
"$bin" decode --profile cyskin_16 --interface vcan0 --duration-s 0.2 > live.txt 2> live.err
status=$?
if [ $status -ne 0 ]; then
  [ $status -eq 1 ] || fail "live decode exit status $status"
  grep -Eq 'AF_CAN|vcan0' live.err || fail "live decode error message: $(cat live.err)"
fi
set -e
echo "decode CLI: all checks passed"
