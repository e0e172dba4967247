#!/usr/bin/env bash
# Bring-up test of the emulated board's UART0: builds the echo firmware (release, `--bin echo`),
# boots it on QEMU with UART0 on one end of a socat PTY pair, sends random bytes into the other
# end, reads the echo back, compares, and reports the round-trip rate in bytes/s.
#
#   boards/qemu-m7/tests/echo.sh [BYTES]        (default 102400, about one QVGA frame)
#
# Environment: DIGITEYES_ICOUNT=1 (passed to run-qemu), ECHO_TIMEOUT=seconds for the transfer
# (default 120; ~15 KB/s is typical, see docs/boards/qemu-m7.md), QEMU=emulator binary.
# Exit status: 0 when every byte came back intact (or, with "SKIPPED", when qemu-system-arm or
# socat is missing), non-zero otherwise; a stalled transfer fails at the timeout. QEMU, socat
# and the reader are always stopped.
set -euo pipefail
board=$(cd "$(dirname "$0")/.." && pwd)
bytes=${1:-102400}
qemu=${QEMU:-qemu-system-arm}
timeout_s=${ECHO_TIMEOUT:-120}

for tool in "$qemu" socat; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIPPED: $tool not found (apt-get install -y qemu-system-arm socat)"
    exit 0
  fi
done

tmp=$(mktemp -d)
pids=()
cleanup() {
  local pid
  for pid in "${pids[@]}"; do
    kill "$pid" 2>/dev/null || true
  done
  for pid in "${pids[@]}"; do
    wait "$pid" 2>/dev/null || true
  done
  rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

(cd "$board" && cargo build --release --quiet --bin echo)
elf=$board/target/thumbv7em-none-eabihf/release/echo

# A PTY pair: QEMU's UART0 on "board", this script on "host"; socat copies between them.
socat pty,raw,echo=0,link="$tmp/board" pty,raw,echo=0,link="$tmp/host" 2>"$tmp/socat.log" &
pids+=($!)
for _ in $(seq 100); do
  [[ -e $tmp/board && -e $tmp/host ]] && break
  sleep 0.05
done
[[ -e $tmp/board && -e $tmp/host ]] || { echo "FAIL: socat made no PTY pair"; cat "$tmp/socat.log"; exit 1; }
stty -F "$tmp/host" raw -echo

DIGITEYES_SERIAL=$tmp/board "$board/run-qemu" "$elf" >"$tmp/qemu.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do
  grep -qs "digiteyes qemu-m7 echo:" "$tmp/qemu.log" && break
  sleep 0.05
done
if ! grep -q "digiteyes qemu-m7 echo:" "$tmp/qemu.log"; then
  echo "FAIL: no boot banner from the firmware"
  cat "$tmp/qemu.log"
  exit 1
fi
sed 's/^/  qemu: /' "$tmp/qemu.log"

head -c "$bytes" /dev/urandom >"$tmp/sent"
# Read the echo on one descriptor while writing on another; both on the same PTY end.
exec 3<"$tmp/host"
start=$(date +%s.%N)
timeout "$timeout_s" head -c "$bytes" <&3 >"$tmp/received" &
reader=$!
pids+=("$reader")
status=0
timeout "$timeout_s" cat "$tmp/sent" >"$tmp/host" || status=$?
wait "$reader" || status=$?
end=$(date +%s.%N)
exec 3<&-

got=$(stat -c %s "$tmp/received")
rate=$(awk -v n="$got" -v s="$start" -v e="$end" 'BEGIN { printf "%.0f", n / (e - s) }')
secs=$(awk -v s="$start" -v e="$end" 'BEGIN { printf "%.2f", e - s }')
if [[ $status -ne 0 || $got -ne $bytes ]]; then
  echo "FAIL: $got of $bytes bytes came back in ${secs} s (status $status; 124: timed out)"
  sed 's/^/  qemu: /' "$tmp/qemu.log"
  exit 1
fi
if ! cmp -s "$tmp/sent" "$tmp/received"; then
  echo "FAIL: the echo differs from what was sent:"
  cmp "$tmp/sent" "$tmp/received" | head -5 || true
  exit 1
fi
echo "ok: $bytes random bytes echoed intact in ${secs} s: $rate bytes/s round trip" \
  "(icount ${DIGITEYES_ICOUNT:-0})"
