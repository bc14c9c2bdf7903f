"""Benchmark: latency of the live explorer, slider change to redrawn page, in headless Chromium.

Starts ``python -m impactbeam explore examples/case03.toml`` on a free port,
opens the page in headless Chromium (the system package, driven by
Playwright), focuses a slider's handle and presses the arrow key ``--moves``
times, one step at a time, waiting for each update to be drawn and settle
before the next.

Everything is timed inside the page on one clock (``performance.now()``):

* ``key``: the keydown event on the slider handle (the slider's value changes
  in the same event handler);
* ``send``: the websocket frame that carries the slider's ``value_throttled``
  (the new value on its way to the server);
* ``answer``: the first frame of the server's update message (``PATCH-DOC``);
  the size of all frames received after ``send`` is summed;
* ``data``: the figures' data source changed in the page (Bokeh's document
  change event);
* ``text``: the moment the metrics table shows the new value of the slider
  (cell ``#v-NAME``; the table is redrawn whole, first-impact time
  included), seen by a MutationObserver on the DOM;
* ``paint``: the end of the last repaint of the two figures (Bokeh's
  ``PlotView._actual_paint``) after their data changed.

The latency of one change is ``max(text, paint) - key``: the time until the
first-impact time and both curves on the screen are the new ones. Its
server-side share is ``answer - send``: the websocket hop, the Bokeh
server's handling of the messages, the simulation, the sampling and
decimation of the curves and the serialisation of the update. The script
prints the median and quartiles of each part, and of the server's own clock
as the metrics table reports it (simulation and metrics, sampling, whole
callback). It prints figures, not pass/fail; the target is about 100 ms.
Two warm-up steps are left out.

Run: ``python benchmarks/bench_explore.py [--moves N] [--slider gap] [--key ArrowRight]``.
"""

from __future__ import annotations

import argparse
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "examples" / "case03.toml"
ARGS = ["--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking",
        "--disable-component-update", "--disable-sync"]

#: Installed before the page's own scripts: records websocket frames and key presses.
INIT_JS = """
window.__ib = {log: []};
(() => {
  const log = (...e) => window.__ib.log.push(e);
  const size = (d) => typeof d === "string" ? d.length : (d.byteLength ?? d.size ?? 0);
  const Orig = window.WebSocket;
  class Timed extends Orig {
    constructor(...a) {
      super(...a);
      this.addEventListener("message", (e) => log("recv", performance.now(), size(e.data), typeof e.data === "string" ? e.data.slice(0, 160) : "<bin>"));
    }
    send(d) { log("send", performance.now(), size(d), typeof d === "string" ? d.slice(0, 300) : "<bin>"); return super.send(d); }
  }
  window.WebSocket = Timed;
  document.addEventListener("keydown", (e) => log("key", performance.now(), e.key), true);
})();
"""

#: Run once the page is up: watches the first-impact cell and the figures' repaints.
WATCH_JS = """(sel) => {
  const log = (...e) => window.__ib.log.push(e);
  const find = (root, sel) => {
    const hit = root.querySelector(sel);
    if (hit) return [hit, root];
    for (const node of root.querySelectorAll("*")) {
      if (node.shadowRoot) { const r = find(node.shadowRoot, sel); if (r) return r; }
    }
    return null;
  };
  const [cell, root] = find(document, sel);
  let last = cell.textContent;
  new MutationObserver(() => {
    const c = root.querySelector(sel);
    if (c && c.textContent !== last) { last = c.textContent; log("text", performance.now(), last); }
  }).observe(root, {subtree: true, childList: true, characterData: true});
  const seen = new Set();
  const walk = (v) => {
    if (!v || seen.has(v)) return;
    seen.add(v);
    if (v.model && v.model.type === "Figure" && typeof v._actual_paint === "function") {
      const paint = v._actual_paint.bind(v);
      v._actual_paint = (...a) => { const r = paint(...a); log("paint", performance.now(), v.model.id); return r; };
    }
    const kids = v.child_views ?? [];
    for (const c of (kids[Symbol.iterator] ? kids : Object.values(kids))) walk(c);
  };
  for (const r of Bokeh.index.roots) walk(r);
  Bokeh.documents[0].on_change((ev) => {
    if (ev.model && ev.model.type === "ColumnDataSource") log("data", performance.now(), ev.model.id);
  });
  return [...seen].filter((v) => v.model && v.model.type === "Figure").length;
}"""


#: Text of the metrics cells with the given ids (the table lives in a shadow root).
CELLS_JS = """(ids) => {
  const find = (root, sel) => {
    const hit = root.querySelector(sel);
    if (hit) return hit;
    for (const node of root.querySelectorAll("*")) {
      if (node.shadowRoot) { const r = find(node.shadowRoot, sel); if (r) return r; }
    }
    return null;
  };
  return ids.map((id) => { const e = find(document, "#" + id); return e ? e.textContent : null; });
}"""

#: Server-side parts read from the page's metrics table: id, label.
SERVER_CELLS = (("m-sim_ms", "simulation and metrics"), ("m-sample_ms", "sampling u and the force"),
                ("m-update_ms", "whole callback"))


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _one(events: list[list]) -> dict[str, float] | None:
    """Times of one update (ms after the key press) from the events logged since the press."""
    key = next((e[1] for e in events if e[0] == "key"), None)
    text = next((e[1] for e in events if e[0] == "text"), None)
    if key is None or text is None:
        return None
    sends = [e for e in events if e[0] == "send" and e[1] >= key]
    send = next((e[1] for e in sends if "value_throttled" in e[3]), sends[0][1] if sends else None)
    recv = [e for e in events if e[0] == "recv" and send is not None and e[1] >= send]
    answer = next((e[1] for e in recv if '"PATCH-DOC"' in e[3]), None)
    data = [e[1] for e in events if e[0] == "data"]
    paints = [e[1] for e in events if e[0] == "paint" and data and e[1] >= data[-1]]
    paint = paints[-1] if paints else float("nan")
    nan = float("nan")
    return {
        "send": send - key if send is not None else nan,
        "server": answer - send if answer is not None and send is not None else nan,
        "answer": answer - key if answer is not None else nan,
        "kB": sum(e[2] for e in recv) / 1e3,
        "frames": float(len(recv)),
        "data": data[-1] - key if data else nan,
        "text": text - key,
        "paint": paint - key,
        "total": max(text, paint) - key,
    }


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print the medians (see the module docstring)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--moves", type=int, default=30, help="slider steps to time (default 30)")
    ap.add_argument("--slider", default="gap", help="slider to move (css class ib-NAME; default gap)")
    ap.add_argument("--key", default="ArrowRight", help="key to press on the handle (default ArrowRight)")
    ap.add_argument("--settle", type=float, default=0.3, help="seconds to wait after each update (default 0.3)")
    ap.add_argument("--scenario", default=str(CASE), help="scenario file (default examples/case03.toml)")
    args = ap.parse_args(argv)

    from playwright.sync_api import Error, sync_playwright

    chromium = shutil.which("chromium") or "/usr/bin/chromium"
    port = _free_port()
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "OMP_NUM_THREADS": "1"}
    server = subprocess.Popen([sys.executable, "-m", "impactbeam", "explore", args.scenario, "--port", str(port)],
                              env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    rows: list[dict[str, float]] = []
    server_ms: list[list[float]] = []
    try:
        with sync_playwright() as pw, tempfile.TemporaryDirectory() as profile:
            ctx = pw.chromium.launch_persistent_context(profile, executable_path=chromium, headless=True, args=ARGS,
                                                        viewport={"width": 1300, "height": 1000})
            page = ctx.new_page()
            page.add_init_script(INIT_JS)
            deadline = time.monotonic() + 120
            while True:
                try:
                    page.goto(f"http://127.0.0.1:{port}/", timeout=10_000)
                    break
                except Error:
                    if server.poll() is not None or time.monotonic() > deadline:
                        raise SystemExit(f"explorer did not start:\n{server.stdout.read() if server.stdout else ''}")
                    time.sleep(1)
            page.locator("#m-first_impact_time").wait_for(timeout=120_000)
            time.sleep(1.0)
            n_fig = page.evaluate(WATCH_JS, f"#v-{args.slider}")
            handle = page.locator(f".ib-{args.slider} .noUi-handle").first
            handle.focus()
            for i in range(args.moves + 2):  # the first two warm up
                start = page.evaluate("() => window.__ib.log.length")
                page.keyboard.press(args.key)
                page.wait_for_function("(n) => window.__ib.log.slice(n).some((e) => e[0] === 'text')", arg=start,
                                       polling=5, timeout=30_000)
                time.sleep(args.settle)
                events = page.evaluate("(n) => window.__ib.log.slice(n)", start)
                one = _one(events)
                if i >= 2 and one is not None:
                    rows.append(one)
                    cells = page.evaluate(CELLS_JS, [c[0] for c in SERVER_CELLS])
                    server_ms.append([float(c.split()[0]) if c else float("nan") for c in cells])
            ctx.close()
    finally:
        server.terminate()
        try:
            server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            server.kill()

    print(f"explorer latency, {len(rows)} steps of the {args.slider} slider ({n_fig} figures), "
          "ms after the key press: median [quartiles]")
    labels = {
        "send": "value sent on the websocket",
        "server": "server share (sent -> update's first frame)",
        "answer": "update's first frame received",
        "data": "figure data applied in the page",
        "text": "metrics table shown",
        "paint": "figures repainted",
        "total": "LATENCY: all shown",
        "kB": "received per change, all frames [kB]",
        "frames": "websocket frames received per change",
    }
    for key, label in labels.items():
        x = np.array([r[key] for r in rows])
        q1, med, q3 = np.nanpercentile(x, [25, 50, 75])
        print(f"  {label:42s} {med:8.1f}  [{q1:.1f}, {q3:.1f}]")
    share = np.median([r["server"] for r in rows]) / np.median([r["total"] for r in rows])
    print(f"  server share of the median latency: {share:.0%}")
    print("server side, its own clock (metrics table), ms: median [quartiles]")
    for (_, label), x in zip(SERVER_CELLS, np.array(server_ms).T):
        if np.isfinite(x).any():
            q1, med, q3 = np.nanpercentile(x, [25, 50, 75])
            print(f"  {label:42s} {med:8.1f}  [{q1:.1f}, {q3:.1f}]")
    return 0


if __name__ == "__main__":
    sys.exit(main())
