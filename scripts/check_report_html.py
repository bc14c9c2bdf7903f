#!/usr/bin/env python3
"""Open a report.html in headless Chromium and confirm that every image loads.

Usage: python scripts/check_report_html.py out/paper/report.html

An inline script is added to a temporary copy of the page: after the load
event it marks the document with the number of <img> elements and the number
whose naturalWidth is 0 (failed to load). Chromium dumps the DOM
(--dump-dom, fresh --user-data-dir, no network), and this script reads the
marks. Exit status: 0 all images loaded; 1 an image failed or no images;
2 bad usage or Chromium not installed.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")

PROBE = """<script>
window.addEventListener('load', function () {
  var imgs = Array.prototype.slice.call(document.images);
  var bad = imgs.filter(function (i) { return !(i.complete && i.naturalWidth > 0); })
                .map(function (i) { return i.getAttribute('src'); });
  var m = document.createElement('pre');
  m.id = 'img-check';
  m.textContent = 'IMGCHECK total=' + imgs.length + ' failed=' + bad.length + ' [' + bad.join(',') + ']';
  document.body.appendChild(m);
});
</script>"""


def find_browser() -> str | None:
    for name in BROWSERS:
        path = shutil.which(name)
        if path:
            return path
    return None


def check(html_path: Path, browser: str, timeout: float = 60.0) -> tuple[int, int, str]:
    """(total images, failed images, detail) as seen by the browser."""
    text = html_path.read_text(encoding="utf-8")
    probe_page = text.replace("</body>", PROBE + "</body>") if "</body>" in text else text + PROBE
    with tempfile.TemporaryDirectory() as profile:
        # the copy sits beside the original so relative image paths resolve
        fd, tmp = tempfile.mkstemp(prefix=".imgcheck-", suffix=".html", dir=html_path.parent)
        try:
            with open(fd, "w", encoding="utf-8") as fh:
                fh.write(probe_page)
            cmd = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                   "--no-first-run", "--disable-component-update", "--disable-sync",
                   f"--user-data-dir={profile}", "--allow-file-access-from-files",
                   "--virtual-time-budget=10000", "--dump-dom", Path(tmp).resolve().as_uri()]
            out = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        finally:
            Path(tmp).unlink(missing_ok=True)
    m = re.search(r"IMGCHECK total=(\d+) failed=(\d+) \[([^\]]*)\]", out.stdout)
    if not m:
        return 0, 0, f"no result from the browser (exit {out.returncode}): {out.stderr.strip()[-500:]}"
    return int(m.group(1)), int(m.group(2)), m.group(3)


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    html_path = Path(argv[1])
    if not html_path.is_file():
        print(f"error: {html_path} does not exist", file=sys.stderr)
        return 2
    browser = find_browser()
    if browser is None:
        print("error: no chromium found (apt-get install chromium)", file=sys.stderr)
        return 2
    total, failed, detail = check(html_path, browser)
    if total == 0:
        print(f"FAIL: no images seen in {html_path} ({detail})")
        return 1
    if failed:
        print(f"FAIL: {failed} of {total} images did not load: {detail}")
        return 1
    print(f"OK: all {total} images in {html_path} loaded in {Path(browser).name}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
