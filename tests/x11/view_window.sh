#!/bin/sh
# The viewer's real window under window events (issue 18: resizing, minimising and closing
# work), run by ctest as test_view_window:
#   view_window.sh ANIMKIT VIEW_WINDOW_POKE
# Under Xvfb, opens `animkit view builtin:cylinder` at 200x150, lets view_window_poke resize
# it to 640x360, unmap and map it, resize it to 300x200 and close it; passes when the viewer
# exits 0 and its --stats line reports frames drawn at 300x200. Exit 77 (ctest SKIP) without
# an SDL2 window build or xvfb-run.
cli=$1
poke=$2
if ! "$cli" view --help 2>&1 | grep -q "This build has a window"; then
  echo "SKIP: this build of animkit has no SDL2 window"; exit 77
fi
if ! command -v xvfb-run >/dev/null 2>&1; then
  echo "SKIP: xvfb-run not found (Debian xvfb, xauth)"; exit 77
fi
inner=$(mktemp) log=$(mktemp)
trap 'rm -f "$inner" "$log"' EXIT
cat > "$inner" <<INNER
#!/bin/sh
# leak checks off for the viewer under ASan: the display stack SDL loads keeps allocations
# LeakSanitizer cannot name (the viewer's own memory is checked by test_view_cli's sessions)
ASAN_OPTIONS=detect_leaks=0 "$cli" view builtin:cylinder --size 200x150 --stats > "$log" 2>&1 &
pid=\$!
if ! "$poke"; then kill \$pid 2>/dev/null; wait \$pid; exit 1; fi
wait \$pid
INNER
timeout 240 xvfb-run -a sh "$inner"
rc=$?
cat "$log"
if [ "$rc" != 0 ]; then echo "FAIL: the viewer (or the poke) exited $rc"; exit 1; fi
if ! grep -q "frames 300x200" "$log"; then
  echo "FAIL: no --stats line with frames drawn at 300x200 after the resizes"; exit 1
fi
echo "ok: resized 200x150 -> 640x360, unmapped, mapped, resized to 300x200, closed; exit 0"
