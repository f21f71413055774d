"""Ctrl-C (SIGINT) during a long render raises KeyboardInterrupt within a second."""

import select
import signal
import subprocess
import sys
import time

# Python installs its KeyboardInterrupt handler only when SIGINT is not ignored at start-up,
# and a job started in the background by a non-interactive shell inherits an ignored SIGINT:
# the child installs the handler itself, as an interactive Python has it.
CHILD = r"""
import signal, sys, time, raylab
signal.signal(signal.SIGINT, signal.default_int_handler)
print("start", flush=True)
t0 = time.time()
try:
    raylab.render(sys.argv[1], width=320, height=240, spp=4096, max_depth=8)
    print("finished", time.time() - t0, flush=True)
except KeyboardInterrupt:
    print("interrupted", flush=True)
"""


def readline(p, timeout):
    ready, _, _ = select.select([p.stdout], [], [], timeout)
    return p.stdout.readline().strip() if ready else None


def test_sigint_raises_keyboard_interrupt_within_a_second(repo):
    p = subprocess.Popen([sys.executable, "-c", CHILD, str(repo / "scenes/cornell_path.toml")], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert readline(p, 120) == "start"
        time.sleep(1.5)  # loading done, the render is under way (it takes minutes)
        assert p.poll() is None
        sent = time.monotonic()
        p.send_signal(signal.SIGINT)
        line = readline(p, 30)
        elapsed = time.monotonic() - sent
        assert line == "interrupted", f"got {line!r} after {elapsed:.1f} s"
        assert elapsed < 1.0, f"KeyboardInterrupt after {elapsed:.2f} s"
    finally:
        p.kill()
        p.wait()
