#!/usr/bin/env bash
# Documented check that lcm-spy works with sedbridge's types: starts a virtual X server
# (Xvfb), plays an LCM log into tools/lcm_spy.sh (LCM's file:// provider, no network),
# double-clicks the DISPLAY_COMMAND row to open its channel viewer (the step that needs
# libjchart2d-java), and saves screenshots.
#   tools/check_lcm_spy.sh LOG OUT_DIR [BUILD_DIR]
# Exit 0: the viewer window opened and lcm-spy logged no exception; the screenshot is
# OUT_DIR/lcm_spy_channel.png. Exit 1: it did not (OUT_DIR/lcm_spy.log says why).
# Exit 77 (skip): Xvfb, xdotool, Java or the types jar are missing (tools/setup.sh installs them).
# Waits are polls with a generous bound, never a fixed sleep that a slow host could miss.
set -u
log=$(realpath "$1"); out=$2; build=${3:-}
root=$(cd "$(dirname "$0")/.." && pwd)
build=${build:-$root/build}
mkdir -p "$out"; out=$(realpath "$out")
for tool in Xvfb xdotool java; do
  command -v $tool >/dev/null || { echo "check_lcm_spy: skip: $tool not installed (tools/setup.sh)"; exit 77; }
done
[ -f "$build/lcmtypes/sedbridge_lcmtypes.jar" ] || { echo "check_lcm_spy: skip: no $build/lcmtypes/sedbridge_lcmtypes.jar"; exit 77; }
[ -f /usr/share/java/jchart2d.jar ] || { echo "check_lcm_spy: skip: libjchart2d-java not installed"; exit 77; }

fbdir=$(mktemp -d)
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; rm -rf "$fbdir"; }
trap cleanup EXIT
# -displayfd: Xvfb picks a free display number and writes it to fd 3.
exec 3> "$fbdir/display"
Xvfb -displayfd 3 -screen 0 1024x768x24 -fbdir "$fbdir" -nolisten tcp >"$out/xvfb.log" 2>&1 &
pids+=($!)
exec 3>&-
poll() {  # poll SECONDS COMMAND...: true once COMMAND succeeds
  local end=$((SECONDS + $1)); shift
  until "$@" >/dev/null 2>&1; do [ $SECONDS -ge $end ] && return 1; sleep 0.2; done
}
poll 30 test -s "$fbdir/display" || { echo "check_lcm_spy: Xvfb did not start"; cat "$out/xvfb.log"; exit 1; }
export DISPLAY=:$(cat "$fbdir/display")

# Only DISPLAY_COMMAND, so it is the table's first row wherever the other channels would sort.
PYTHONPATH="$root/tools" python3 - "$log" "$fbdir/commands.lcmlog" <<'PY'
import sys, sedbridge_lcm
with sedbridge_lcm.EventLog(sys.argv[2], "w") as out:
    for e in sedbridge_lcm.EventLog(sys.argv[1]):
        if e.channel == "DISPLAY_COMMAND":
            out.write_event(e.timestamp, e.channel, e.data)
PY
# speed=0.01: a 3 s log plays for 5 minutes, so the channel stays live (and the log provider
# never reaches its end, which it reports as an exception) however slow the host is.
"$root/tools/lcm_spy.sh" "$build" "--lcm-url=file://$fbdir/commands.lcmlog?speed=0.01" >"$out/lcm_spy.log" 2>&1 &
pids+=($!)
poll 60 xdotool search --name '^LCM Spy$' || { echo "check_lcm_spy: no LCM Spy window"; cat "$out/lcm_spy.log"; exit 1; }
window=$(xdotool search --name '^LCM Spy$' | head -1)
open_viewer() {  # double-click the first row until its viewer window exists
  xdotool mousemove --window "$window" 60 27 click --repeat 2 --delay 80 1
  sleep 1
  xdotool search --name '^DISPLAY_COMMAND$'
}
poll 60 open_viewer
if ! xdotool search --name '^DISPLAY_COMMAND$' >/dev/null; then
  echo "check_lcm_spy: the DISPLAY_COMMAND viewer did not open"; cat "$out/lcm_spy.log"; exit 1
fi
sleep 2   # let the viewer draw its first values
python3 "$root/tools/xwd_to_png.py" "$fbdir/Xvfb_screen0" "$out/lcm_spy_channel.png" --crop 0,0,800,600
if grep -E 'Exception|Error' "$out/lcm_spy.log"; then
  echo "check_lcm_spy: lcm-spy logged an exception (missing jchart2d? see $out/lcm_spy.log)"; exit 1
fi
echo "check_lcm_spy: ok: $out/lcm_spy_channel.png"
