#!/usr/bin/env python3
"""`pathlab view` in headless Chromium (ChromeDriver through Selenium), as a user sees it.

Starts `pathlab view` on a free port, then checks: the page shows the image (the canvas's pixels
in a screenshot are the film's values through the sRGB curve); the value printed under a cursor
that Selenium moves over a pixel equals, to the float, that pixel of the image the render writes
(-o, a PFM); switching the integrator in the page restarts the render with it; the A/B view
starts a second estimator and the RMSE curve grows; requests that try to leave the page's files
are refused, over a raw socket so that nothing normalises them first; Ctrl-C ends the command
with exit code 0 and the output written.

Usage: view_test.py --pathlab build/pathlab [--keep DIR]   (exit 77: skipped, no browser)
"""
import argparse
import http.client
import io
import json
import math
import os
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import urllib.request

SKIP = 77


def read_pfm(path):
    """(width, height, rows top first of [r, g, b] floats)."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind != b"PF":
            raise ValueError(f"{path}: not an RGB PFM")
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        fmt = "<" if scale < 0 else ">"
        data = struct.unpack(f"{fmt}{3 * width * height}f", f.read(12 * width * height))
    rows = [[list(data[3 * (y * width + x):3 * (y * width + x) + 3]) for x in range(width)] for y in range(height)]
    return width, height, rows[::-1]  # PFM rows go bottom to top


def srgb8(v):
    v = min(1.0, max(0.0, v))
    v = 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055
    return round(255 * v)


def raw_get(port, target, host="127.0.0.1"):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    c.putrequest("GET", target, skip_host=True, skip_accept_encoding=True)
    c.putheader("Host", f"{host}:{port}")
    c.endheaders()
    r = c.getresponse()
    body = r.read()
    c.close()
    return r.status, body


def state(url):
    with urllib.request.urlopen(url + "api/state", timeout=10) as r:
        return json.load(r)


def wait_for(what, predicate, seconds=60):
    end = time.time() + seconds
    while time.time() < end:
        value = predicate()
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pathlab", required=True)
    ap.add_argument("--keep", help="keep the screenshots here")
    args = ap.parse_args()
    try:
        from selenium import webdriver
        from selenium.webdriver.common.action_chains import ActionChains
        from selenium.webdriver.common.by import By
        from selenium.webdriver.chrome.service import Service
        from selenium.webdriver.support.ui import Select
        from PIL import Image
    except ImportError as e:
        print(f"skipped: {e} (scripts/install-deps.sh installs python3-selenium and python3-pil)")
        return SKIP
    if not (os.path.exists("/usr/bin/chromium") and os.path.exists("/usr/bin/chromedriver")):
        print("skipped: /usr/bin/chromium or /usr/bin/chromedriver absent (scripts/install-deps.sh installs them)")
        return SKIP

    tmp = tempfile.mkdtemp(prefix="pathlab-view-")
    out = os.path.join(tmp, "view.pfm")
    width, height, spp = 40, 30, 16
    proc = subprocess.Popen([args.pathlab, "view", "3", "-a", "pt-mis", "--spp", str(spp), "--resolution", f"{width}x{height}",
                             "--port", "0", "-o", out, "-q"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    driver = None
    failures = []

    def check(ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            failures.append(what)

    try:
        url = proc.stdout.readline().strip()
        if not url.startswith("http://127.0.0.1:"):
            raise AssertionError(f"pathlab view printed {url!r}; stderr: {proc.stderr.read()}")
        port = int(url.rstrip("/").rsplit(":", 1)[1])

        # Paths that leave the page's files, sent as they are.
        secret = b"cmake_minimum_required"
        for target in ["/../CMakeLists.txt", "/%2e%2e/CMakeLists.txt", "/view.js/../../CMakeLists.txt", "/..%2fCMakeLists.txt",
                       "/%2E%2E%5C%2E%2E%5CCMakeLists.txt"]:
            status, body = raw_get(port, target)
            check(status == 400 and secret not in body, f"GET {target} refused ({status})")
        status, body = raw_get(port, "/CMakeLists.txt")
        check(status == 404 and secret not in body, f"GET /CMakeLists.txt is not one of the page's files ({status})")
        status, _ = raw_get(port, "/", host="rebound.example")
        check(status == 403, f"a request for another Host refused ({status})")

        options = webdriver.ChromeOptions()
        options.binary_location = "/usr/bin/chromium"
        for a in ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1280,900",
                  "--force-device-scale-factor=1"]:
            options.add_argument(a)
        driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
        driver.set_page_load_timeout(30)
        t0 = time.time()
        driver.get(url)
        status_a = driver.find_element(By.ID, "status-a")
        canvas = driver.find_element(By.ID, "image")
        wait_for("the first image", lambda: int(canvas.get_attribute("data-frame") or 0) > 0)
        print(f"     first image in the page {time.time() - t0:.2f} s after it was opened")
        wait_for("the render to finish", lambda: status_a.get_attribute("data-status") == "done")
        final = state(url)["slots"][0]["frame"]
        wait_for("the final image drawn", lambda: int(canvas.get_attribute("data-frame") or 0) == final)
        wait_for("the output", lambda: os.path.exists(out))
        w, h, film = read_pfm(out)
        check((w, h) == (width, height), f"the output is {w}x{h}")

        # The screenshot shows the image: canvas pixels = the film through the sRGB curve (zoom 1).
        shot = Image.open(io.BytesIO(canvas.screenshot_as_png)).convert("RGB")
        if args.keep:
            os.makedirs(args.keep, exist_ok=True)
            shot.save(os.path.join(args.keep, "view-canvas.png"))
        check(shot.size == (width, height), f"the canvas screenshot is {shot.size}")
        worst = 0
        for y in range(0, height, 3):
            for x in range(0, width, 3):
                expected = [srgb8(c) for c in film[y][x]]
                worst = max(worst, max(abs(a - b) for a, b in zip(shot.getpixel((x, y)), expected)))
        check(worst <= 1, f"screenshot pixels equal the film in sRGB (largest difference {worst}/255)")

        # The value under a cursor moved by Selenium (zoomed in 8x) equals the film's.
        for _ in range(3):
            driver.find_element(By.ID, "zoom-in").click()
        zoom = 8
        readout = driver.find_element(By.ID, "pixel")
        for (px, py) in [(5, 7), (31, 20), (20, 3)]:
            dx = (px + 0.5) * zoom - width * zoom / 2
            dy = (py + 0.5) * zoom - height * zoom / 2
            ActionChains(driver).move_to_element_with_offset(canvas, int(dx), int(dy)).perform()
            wait_for("the readout", lambda: readout.get_attribute("data-x") == str(px) and readout.get_attribute("data-y") == str(py), 10)
            shown = [float(v) for v in readout.get_attribute("data-rgb").split()]
            check(shown == film[py][px],
                  f"value under the cursor at ({px}, {py}) {shown} = the film's {film[py][px]}; text '{readout.text}'")

        # Switching the integrator restarts the render with it.
        Select(driver.find_element(By.ID, "algorithm-a")).select_by_value("pt-naive")
        driver.find_element(By.ID, "restart-a").click()
        wait_for("the restart", lambda: status_a.get_attribute("data-algorithm") == "pt-naive" and status_a.get_attribute("data-render") == "2")
        wait_for("pt-naive's image", lambda: status_a.get_attribute("data-status") == "done")
        check("pt-naive" in status_a.text, f"the status names the new integrator: '{status_a.text}'")

        # The A/B view: B started from the page, then the error image and the curve of A - B.
        Select(driver.find_element(By.ID, "algorithm-b")).select_by_value("lt")
        driver.find_element(By.ID, "restart-b").click()
        wait_for("B's image", lambda: state(url)["slots"][1]["frame"] > 0)
        # Restart A so that its images come after B's (the curve is A against B).
        driver.find_element(By.ID, "restart-a").click()
        s = wait_for("the A - B curve", lambda: (lambda j: j if j["slots"][0]["rmse"] else None)(state(url)))
        check(s["slots"][1]["algorithm"] == "lt" and len(s["slots"][0]["rmse"]) > 0, "B renders lt and the A - B curve has points")
        Select(driver.find_element(By.ID, "show")).select_by_value("error")
        if args.keep:
            driver.save_screenshot(os.path.join(args.keep, "view-page.png"))
        driver.find_element(By.ID, "stop-b").click()
        wait_for("B stopped", lambda: not state(url)["slots"][1]["active"])
    finally:
        if driver:
            driver.quit()
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
        try:
            code = proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()
            code = None
        check(code == 0, f"Ctrl-C ends pathlab view with exit code 0 (got {code})")
        check(os.path.exists(out), "the output exists after Ctrl-C")
        shutil.rmtree(tmp, ignore_errors=True)
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
