#!/usr/bin/env python3
"""A bounded load test of `sweepclay serve` on loopback: starts the release
binary on a free port, sends N concurrent POST /api/slice of t1 (200 by
default, once each; it stops by itself), and prints p50/p99 latency, the
answers by status, and the server's peak resident memory.

    cargo build --release && python3 scripts/load.py [N]
"""
import concurrent.futures
import json
import os
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "sweepclay")
N = int(sys.argv[1]) if len(sys.argv) > 1 else 200


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def main():
    port = free_port()
    server = subprocess.Popen([BIN, "serve", "--port", str(port)], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    try:
        base = f"http://127.0.0.1:{port}"
        for _ in range(100):
            try:
                urllib.request.urlopen(base + "/api/meta", timeout=1).read()
                break
            except OSError:
                time.sleep(0.05)
        with open(os.path.join(ROOT, "examples", "t1.json"), "rb") as f:
            body = f.read()

        def one(_):
            req = urllib.request.Request(base + "/api/slice", data=body, headers={"content-type": "application/json"})
            t = time.perf_counter()
            try:
                with urllib.request.urlopen(req, timeout=120) as r:
                    r.read()
                    code = r.status
            except urllib.error.HTTPError as e:
                code = e.code
            except OSError:
                code = "connection error"
            return code, time.perf_counter() - t

        t0 = time.perf_counter()
        with concurrent.futures.ThreadPoolExecutor(max_workers=N) as pool:
            results = list(pool.map(one, range(N)))
        wall = time.perf_counter() - t0
        with open(f"/proc/{server.pid}/status") as f:
            peak = next(l for l in f if l.startswith("VmHWM")).split()[1]
        ok = sorted(t for c, t in results if c == 200)
        codes = {}
        for c, _ in results:
            codes[str(c)] = codes.get(str(c), 0) + 1
        pct = lambda p: ok[min(len(ok) - 1, int(p * len(ok)))] * 1000 if ok else float("nan")
        print(f"{N} concurrent t1 slices in {wall:.1f} s: answers {json.dumps(codes)}")
        print(f"  200s: p50 {pct(0.5):.0f} ms, p99 {pct(0.99):.0f} ms")
        print(f"  server peak resident memory {int(peak) / 1024:.0f} MB")
    finally:
        server.terminate()
        server.wait()


if __name__ == "__main__":
    main()
