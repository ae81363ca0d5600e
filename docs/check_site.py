"""Check that the documentation site renders: build it, serve it, screenshot three pages.

    python docs/check_site.py                  # build into a temporary folder, then check
    python docs/check_site.py --site site      # check a site built already
    python docs/check_site.py --out shots      # keep the screenshots there

Builds the site with ``mkdocs build --strict`` (unless ``--site`` is given), serves it with
``python -m http.server`` on localhost, and takes a screenshot of the home page, the top-level API
page and the quickstart notebook's page with headless Chromium (Debian: ``apt-get install
chromium``). Fails (exit code 1) if a page is not served, lacks its expected text, or its
screenshot is missing or blank (a single colour, or almost nothing but the background).
Not part of CI, whose machine may lack Chromium; CI runs ``mkdocs build --strict`` only.
"""

from __future__ import annotations

import argparse
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: (page path under the site, text its HTML must contain, screenshot file name)
PAGES = (
    ("", "jaxgear", "index.png"),
    ("api/", "jaxgear.simulate", "api.png"),
    ("examples/quickstart/", "quickstart", "notebook.png"),
)
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
WINDOW = (1280, 1600)
#: a screenshot passes if its pixels are not all one colour and at least this share of them
#: differs from the most common (background) colour
MIN_INK_SHARE = 0.01


def build_site(site: Path) -> None:
    command = [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)]
    print("building:", " ".join(command), flush=True)
    subprocess.run(command, cwd=ROOT, check=True)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_until_served(url: str, timeout: float = 20.0) -> None:
    deadline = time.monotonic() + timeout
    while True:
        try:
            with urllib.request.urlopen(url, timeout=2.0):
                return
        except (urllib.error.URLError, ConnectionError):
            if time.monotonic() > deadline:
                raise RuntimeError(f"{url} was not served within {timeout:.0f} s") from None
            time.sleep(0.2)


def fetch(url: str) -> str:
    with urllib.request.urlopen(url, timeout=10.0) as response:
        return response.read().decode("utf-8", errors="replace")


def find_chromium(given: str | None) -> str:
    for name in (given,) if given else CHROMIUM_NAMES:
        path = shutil.which(name)
        if path:
            return path
    raise RuntimeError(
        "no Chromium found (tried " + ", ".join((given,) if given else CHROMIUM_NAMES) + "); "
        "on Debian: apt-get install chromium"
    )


def screenshot(chromium: str, url: str, png: Path) -> None:
    with tempfile.TemporaryDirectory(prefix="chromium-profile-") as profile:
        command = [
            chromium,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--virtual-time-budget=5000",  # let the page's scripts run before the shot
            f"--user-data-dir={profile}",
            f"--screenshot={png}",
            f"--window-size={WINDOW[0]},{WINDOW[1]}",
            url,
        ]
        subprocess.run(command, check=True, capture_output=True, timeout=180)


def blank_reason(png: Path) -> str | None:
    """Why the screenshot ``png`` is missing or blank, or None if it shows something."""
    if not png.is_file() or png.stat().st_size == 0:
        return "no screenshot written"
    import matplotlib.image
    import numpy as np

    image = matplotlib.image.imread(png)
    if image.ndim != 3 or image.shape[0] < 100 or image.shape[1] < 100:
        return f"unexpected image shape {image.shape}"
    pixels = image[..., :3].reshape(-1, 3)
    colours, counts = np.unique(np.round(pixels * 255).astype(np.uint8), axis=0, return_counts=True)
    if len(colours) == 1:
        return "a single colour"
    ink = 1.0 - counts.max() / counts.sum()
    if ink < MIN_INK_SHARE:
        return f"only {100 * ink:.2f} % of the pixels differ from the background"
    return None


def check(site: Path, out: Path, chromium: str) -> list[str]:
    port = free_port()
    base = f"http://127.0.0.1:{port}/"
    server = subprocess.Popen(
        [sys.executable, "-m", "http.server", str(port), "--bind", "127.0.0.1",
         "--directory", str(site)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )  # fmt: skip
    failures = []
    try:
        wait_until_served(base)
        for path, text, name in PAGES:
            url = base + path
            try:
                html = fetch(url)
            except urllib.error.URLError as err:
                failures.append(f"{url}: not served ({err})")
                continue
            if text not in html:
                failures.append(f"{url}: the page lacks {text!r}")
            png = out / name
            try:
                screenshot(chromium, url, png)
            except (subprocess.CalledProcessError, subprocess.TimeoutExpired) as err:
                failures.append(f"{url}: Chromium failed ({err})")
                continue
            reason = blank_reason(png)
            if reason:
                failures.append(f"{url}: screenshot {png} is blank: {reason}")
            else:
                print(f"ok  {url} -> {png} ({png.stat().st_size // 1024} kB)", flush=True)
    finally:
        server.terminate()
        server.wait(timeout=10)
    return failures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--site", type=Path, help="a built site (default: build one)")
    parser.add_argument("--out", type=Path, help="folder for the screenshots (default: temporary)")
    parser.add_argument("--chromium", help="the Chromium executable (default: found on PATH)")
    args = parser.parse_args(argv)

    chromium = find_chromium(args.chromium)
    with tempfile.TemporaryDirectory(prefix="jaxgear-site-") as tmp:
        site = args.site
        if site is None:
            site = Path(tmp) / "site"
            build_site(site)
        if not (site / "index.html").is_file():
            print(f"{site} holds no built site (index.html missing)", file=sys.stderr)
            return 1
        out = args.out if args.out is not None else Path(tmp) / "screenshots"
        out.mkdir(parents=True, exist_ok=True)
        failures = check(site.resolve(), out, chromium)
        if args.out is None:
            print("screenshots were temporary: pass --out DIR to keep them")
    for failure in failures:
        print("FAIL", failure, file=sys.stderr)
    print("site check:", "failed" if failures else "ok")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
