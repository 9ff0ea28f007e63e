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
cleanup() {
  [ -z "$child_pid" ] || kill "$child_pid" 2>/dev/null || true
  if [ -n "$xvfb_pid" ]; then
    kill "$xvfb_pid" 2>/dev/null || true
    wait "$xvfb_pid" 2>/dev/null || true
  fi
  rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 143' TERM
trap 'exit 130' INT

mkfifo "$tmp/displayfd"
Xvfb -displayfd 3 -nolisten tcp -screen 0 "$screen" 3>"$tmp/displayfd" 2>"$tmp/xvfb.log" &
xvfb_pid=$!
display=""
# The read ends at Xvfb's newline, or empty at EOF if Xvfb exits first.
read -r -t 60 display <"$tmp/displayfd" || true
if ! [[ "$display" =~ ^[0-9]+$ ]]; then
  echo "FAILED: Xvfb did not start (no display number within 60 s):" >&2
  cat "$tmp/xvfb.log" >&2
  exit 1
fi

# In the background, so a TERM from ctest or the user runs the cleanup at once.
DISPLAY=":$display" "$@" &
child_pid=$!
rc=0
wait "$child_pid" || rc=$?
child_pid=""
exit "$rc"
