"""Ctrl-C (SIGINT) during a long render raises KeyboardInterrupt within a second."""

import signal
import subprocess
import sys
import time

CHILD = r"""
import sys, time, raylab
print("start", flush=True)
t0 = time.time()
try:
    raylab.render(sys.argv[1], width=320, height=240, spp=4096, max_depth=8)
    print("finished", time.time() - t0, flush=True)
except KeyboardInterrupt:
    print("interrupted", flush=True)
"""


def test_sigint_raises_keyboard_interrupt_within_a_second(repo):
    p = subprocess.Popen([sys.executable, "-c", CHILD, str(repo / "scenes/cornell_path.toml")], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "start"
        time.sleep(1.5)  # loading done, the render is under way (it takes minutes)
        assert p.poll() is None
        sent = time.monotonic()
        p.send_signal(signal.SIGINT)
        line = p.stdout.readline().strip()
        elapsed = time.monotonic() - sent
        assert line == "interrupted", p.stderr.read()
        assert elapsed < 1.0, f"KeyboardInterrupt after {elapsed:.2f} s"
    finally:
        p.kill()
        p.wait()
