#!/usr/bin/env bash
# Runs a command with DISPLAY set to a private Xvfb, which it stops afterwards.
#   bash .ci/with-xvfb.sh [-s WxHxD] command args...
# Xvfb chooses its own display (-displayfd): it takes the first number whose lock file and
# sockets it can actually create, and names it only once it accepts connections. `xvfb-run -a`
# instead guesses from /tmp/.X*-lock files alone, so it cannot see a server of another job that
# shares the network namespace (X's abstract sockets) but not /tmp; its Xvfb then fails to bind,
# and the command talks to the other server and dies with "bad X server connection".
set -euo pipefail

screen=1280x1024x24
if [ "${1:-}" = "-s" ]; then
  screen="$2"
  shift 2
fi
[ $# -gt 0 ] || { echo "usage: $0 [-s WxHxD] command args..." >&2; exit 2; }

tmp="$(mktemp -d)"
xvfb_pid=""
child_pid=""
holders=() # processes holding the sockets of displays that did not open
cleanup() {
  [ -z "$child_pid" ] || kill "$child_pid" 2>/dev/null || true
  if [ -n "$xvfb_pid" ]; then
    kill "$xvfb_pid" 2>/dev/null || true
    wait "$xvfb_pid" 2>/dev/null || true
  fi
  for holder in "${holders[@]}"; do
    kill "$holder" 2>/dev/null || true
  done
  rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 143' TERM
trap 'exit 130' INT

# Whether a client can open the display with libX11's XOpenDisplay, as VTK does.
x_opens() {
  python3 -c '
import ctypes, sys
x = ctypes.cdll.LoadLibrary("libX11.so.6")
x.XOpenDisplay.restype = ctypes.c_void_p
x.XOpenDisplay.argtypes = [ctypes.c_char_p]
x.XCloseDisplay.argtypes = [ctypes.c_void_p]
d = x.XOpenDisplay(sys.argv[1].encode())
if d:
    x.XCloseDisplay(d)
sys.exit(0 if d else 1)' "$1" 2>/dev/null
}

# A display whose Xvfb started but that a client cannot open (in CI, once, at random: a
# server of another job answering on the same number, or one not yet ready) gets a fresh
# Xvfb. Xvfb -displayfd skips a number whose abstract socket is taken (its lock files do not
# stop it), so a process of ours holds that socket until the end.
hold_display() {
  python3 -c '
import socket, sys, time
s = socket.socket(socket.AF_UNIX)
s.bind("\0/tmp/.X11-unix/X" + sys.argv[1])
s.listen(1)
time.sleep(86400)' "$1" 2>/dev/null &
  holders+=($!)
}

start_xvfb() {
  rm -f "$tmp/displayfd"
  mkfifo "$tmp/displayfd"
  # -noreset: by default Xvfb resets when its last client leaves, as the probe below does;
  # a client connecting during that reset (slower under load) is refused.
  Xvfb -displayfd 3 -nolisten tcp -noreset -screen 0 "$screen" 3>"$tmp/displayfd" 2>"$tmp/xvfb.log" &
  xvfb_pid=$!
  display=""
  # The read ends at Xvfb's newline, or empty at EOF if Xvfb exits first.
  read -r -t 60 display <"$tmp/displayfd" || true
  if ! [[ "$display" =~ ^[0-9]+$ ]]; then
    echo "FAILED: Xvfb did not start (no display number within 60 s):" >&2
    cat "$tmp/xvfb.log" >&2
    exit 1
  fi
}

for attempt in 1 2 3; do
  start_xvfb
  for wait in 1 2 3 4 5; do
    if x_opens ":$display"; then
      break 2
    fi
    sleep 0.2
  done
  echo "with-xvfb: display :$display started but does not open (attempt $attempt); trying another" >&2
  kill "$xvfb_pid" 2>/dev/null || true
  wait "$xvfb_pid" 2>/dev/null || true
  xvfb_pid=""
  hold_display "$display"
  sleep 0.2
  [ "$attempt" -lt 3 ] || { echo "FAILED: no display that opens after 3 Xvfb" >&2; exit 1; }
done

# In the background, so a TERM from ctest or the user runs the cleanup at once.
DISPLAY=":$display" "$@" &
child_pid=$!
rc=0
wait "$child_pid" || rc=$?
child_pid=""
if [ "$rc" -ne 0 ]; then
  # For the diagnosis of a failure that involves the display.
  state="running"
  kill -0 "$xvfb_pid" 2>/dev/null || state="no longer running"
  echo "with-xvfb: the command exited with $rc on display :$display (Xvfb $state); Xvfb's log:" >&2
  cat "$tmp/xvfb.log" >&2
fi
exit "$rc"
