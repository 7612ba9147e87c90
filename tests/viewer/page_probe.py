#!/usr/bin/env python3
"""Loads a page in headless Chromium, waits until a JavaScript condition holds, then screenshots it.

Drives Chromium over the DevTools protocol through --remote-debugging-pipe (JSON messages,
NUL-terminated, on file descriptors 3 and 4): the standard library is enough, no WebSocket
client or npm package. Prints the value of --report (JSON) when the condition held; logs every
URL the page requested (Network.requestWillBeSent; data: URLs, decoded in place, left out) to
--requests. With --then, reports (and takes the screenshot) when --until holds and reports
again when --then holds. With --ready-file, starts the browser first and loads the page as
soon as the server answers. With --metrics FILE, writes where the browser spent its CPU (JSON):
the page's Performance.getMetrics (ScriptDuration, LayoutDuration, RecalcStyleDuration,
TaskDuration, ...), the CPU seconds of the Chromium processes by --type (browser, renderer,
gpu-process, utility) and of their busiest threads, from /proc, and with --js-profile the
JavaScript functions with the most self time (Profiler). SIGTERM ends the wait but still
reports, writes the metrics and closes the browser. Exits 1 when a condition did not hold
within --timeout seconds (the screenshot is still taken, for a look at why).

  page_probe.py URL --until 'window.orbisScene.loopClosures >= 1' --screenshot shot.png
"""
import argparse
import base64
import fcntl
import json
import os
import re
import signal
import select
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request


class Chromium:
    def __init__(self, binary, width, height, profile, extra_args=()):
        to_browser_r, self._to_browser = os.pipe()
        self._from_browser, from_browser_w = os.pipe()

        def child_fds():  # the browser reads commands on fd 3 and writes answers on fd 4
            r = fcntl.fcntl(to_browser_r, fcntl.F_DUPFD, 10)
            w = fcntl.fcntl(from_browser_w, fcntl.F_DUPFD, 10)
            os.dup2(r, 3)
            os.dup2(w, 4)

        self.process = subprocess.Popen(
            [binary, "--headless", "--disable-gpu", "--no-sandbox", "--hide-scrollbars",
             "--window-size=%d,%d" % (width, height), "--user-data-dir=" + profile,
             "--remote-debugging-pipe", *extra_args, "about:blank"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            preexec_fn=child_fds, close_fds=False)
        os.close(to_browser_r)
        os.close(from_browser_w)
        self._buffer = b""
        self._next_id = 0
        self.events = []

    def _read_message(self, deadline):
        while b"\0" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self._from_browser], [], [], left)[0]:
                raise TimeoutError("no answer from chromium")
            chunk = os.read(self._from_browser, 1 << 20)
            if not chunk:
                raise EOFError("chromium closed the pipe")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method, params=None, session=None, timeout=30):
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self._to_browser, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            answer = self._read_message(deadline)
            if answer.get("id") == self._next_id:
                if "error" in answer:
                    raise RuntimeError("%s: %s" % (method, answer["error"]))
                return answer.get("result", {})
            self.events.append(answer)

    def close(self):
        try:
            self.call("Browser.close", timeout=5)
        except Exception:
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def cpu_seconds(stat_fields, ticks):
    """User + system CPU seconds from the fields of /proc/.../stat after "(comm)"."""
    return (int(stat_fields[11]) + int(stat_fields[12])) / ticks  # utime, stime


def process_tree_cpu(root_pid):
    """CPU seconds (user + system) of root_pid and its descendants, summed by Chromium --type."""
    ticks = os.sysconf("SC_CLK_TCK")
    parents, cpu, kinds = {}, {}, {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % entry) as f:
                fields = f.read().rsplit(")", 1)[1].split()
            with open("/proc/%s/cmdline" % entry, "rb") as f:
                argv = f.read().split(b"\0")
        except OSError:
            continue
        pid = int(entry)
        parents[pid] = int(fields[1])
        cpu[pid] = cpu_seconds(fields, ticks)
        # Chromium rewrites its children's titles: the arguments may come as one string.
        kind = re.search(rb"--type=([\w-]+)", b" ".join(argv))
        kinds[pid] = kind.group(1).decode() if kind else "browser"
    by_kind, by_thread = {}, {}
    for pid in cpu:
        ancestor = pid
        while ancestor not in (root_pid, 0, 1) and ancestor in parents:
            ancestor = parents[ancestor]
        if ancestor != root_pid:
            continue
        by_kind[kinds[pid]] = round(by_kind.get(kinds[pid], 0) + cpu[pid], 3)
        for name, seconds in thread_cpu(pid, ticks).items():
            key = "%s/%s" % (kinds[pid], name)
            by_thread[key] = round(by_thread.get(key, 0) + seconds, 3)
    busiest = dict(sorted(((k, v) for k, v in by_thread.items() if v >= 0.05), key=lambda x: -x[1]))
    return by_kind, busiest


def thread_cpu(pid, ticks):
    """CPU seconds of a process's threads by name (numbered workers summed)."""
    seconds = {}
    try:
        tasks = os.listdir("/proc/%d/task" % pid)
    except OSError:
        return seconds
    for task in tasks:
        try:
            with open("/proc/%d/task/%s/stat" % (pid, task)) as f:
                head, tail = f.read().rsplit(")", 1)
        except OSError:
            continue
        name = re.sub(r"\d+$", "", head.split("(", 1)[1])
        seconds[name] = seconds.get(name, 0) + cpu_seconds(tail.split(), ticks)
    return seconds


def top_functions(profile, count=15):
    """The functions with the most self time in a Profiler.stop profile: [(ms, name url:line)]."""
    nodes = {n["id"]: n for n in profile["nodes"]}
    self_us = {}
    deltas = profile.get("timeDeltas", [])
    for sample, delta in zip(profile.get("samples", []), deltas[1:] + [0]):
        self_us[sample] = self_us.get(sample, 0) + delta
    by_name = {}
    for node_id, us in self_us.items():
        frame = nodes[node_id]["callFrame"]
        name = "%s %s:%d" % (frame["functionName"] or "(anonymous)", frame["url"].rsplit("/", 1)[-1],
                             frame["lineNumber"] + 1)
        by_name[name] = by_name.get(name, 0) + us
    return [(round(us / 1000, 1), name) for name, us in sorted(by_name.items(), key=lambda x: -x[1])[:count]]


def wait_for_url(url, deadline):
    while time.monotonic() < deadline:
        try:
            urllib.request.urlopen(url, timeout=1).close()
            return
        except urllib.error.HTTPError:  # an answer all the same
            return
        except OSError:
            time.sleep(0.05)


class Stopped(Exception):
    """SIGTERM: stop waiting, but still report, write the metrics and close the browser."""


def stop_on_sigterm(signum, frame):
    raise Stopped()


def wait_until(evaluate, expression, deadline, poll, settle):
    """Whether the page's `expression` became true before `deadline`; then `settle` seconds more."""
    while time.monotonic() < deadline:
        if evaluate("Boolean(%s)" % expression) is True:
            time.sleep(settle)
            return True
        time.sleep(poll)
    return False


def take_screenshot(browser, session, path):
    if path:
        shot = browser.call("Page.captureScreenshot", {"format": "png"}, session=session)
        with open(path, "wb") as f:
            f.write(base64.b64decode(shot["data"]))


def write_metrics(browser, session, args, cpu_before_page):
    metrics = browser.call("Performance.getMetrics", session=session)["metrics"]
    by_kind, by_thread = process_tree_cpu(browser.process.pid)
    result = {"page": {m["name"]: m["value"] for m in metrics}, "cpu_seconds": by_kind,
              "cpu_seconds_before_page": cpu_before_page, "cpu_seconds_by_thread": by_thread}
    if args.js_profile:
        result["js_self_ms"] = top_functions(browser.call("Profiler.stop", session=session)["profile"])
    with open(args.metrics, "w") as f:
        json.dump(result, f, indent=1)


def parse_arguments():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("url")
    parser.add_argument("--until", default="true", help="JavaScript expression to wait for")
    parser.add_argument("--then", help="with --until: print the report and take the screenshot when --until "
                        "holds, then wait for this expression too and print the report again")
    parser.add_argument("--report", default="JSON.stringify(window.orbisScene)", help="JavaScript expression to print")
    parser.add_argument("--screenshot", help="PNG file")
    parser.add_argument("--requests", help="file: every URL the page requested, one a line")
    parser.add_argument("--timeout", type=float, default=120)
    parser.add_argument("--ready-file", help="written once the browser has started; then the page is loaded as soon "
                        "as URL answers (so a benchmark can start the browser before the server)")
    parser.add_argument("--poll", type=float, default=0.2, help="seconds between two checks of --until")
    parser.add_argument("--settle", type=float, default=0.5, help="seconds between the condition and the shot")
    parser.add_argument("--size", default="1400x800")
    parser.add_argument("--chromium", default=shutil.which("chromium") or shutil.which("chromium-browser"))
    parser.add_argument("--metrics", help="JSON file: the page's Performance metrics and the browser's CPU")
    parser.add_argument("--js-profile", action="store_true", help="with --metrics: sample JavaScript (Profiler)")
    parser.add_argument("--chromium-arg", action="append", default=[], help="one more Chromium flag (repeatable)")
    return parser.parse_args()


def main():
    args = parse_arguments()
    width, height = map(int, args.size.split("x"))
    profile = tempfile.mkdtemp(prefix="page_probe_")
    browser = Chromium(args.chromium, width, height, profile, args.chromium_arg)
    held = False
    try:
        target = browser.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = browser.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        evaluate = lambda expression: browser.call(
            "Runtime.evaluate", {"expression": expression, "returnByValue": True}, session=session
        ).get("result", {}).get("value")
        browser.call("Network.enable", session=session)
        browser.call("Page.enable", session=session)
        if args.metrics:
            browser.call("Performance.enable", session=session)
            if args.js_profile:
                browser.call("Profiler.enable", session=session)
                browser.call("Profiler.start", session=session)
        cpu_before_page = {}
        if args.ready_file:
            cpu_before_page = process_tree_cpu(browser.process.pid)[0]
            open(args.ready_file, "w").close()
            wait_for_url(args.url, time.monotonic() + args.timeout)
        browser.call("Page.navigate", {"url": args.url}, session=session)
        deadline = time.monotonic() + args.timeout
        signal.signal(signal.SIGTERM, stop_on_sigterm)
        try:
            held = wait_until(evaluate, args.until, deadline, args.poll, args.settle)
            if args.then:  # the first report and the screenshot now, the last one below
                print(evaluate(args.report), flush=True)
                take_screenshot(browser, session, args.screenshot)
                held = wait_until(evaluate, args.then, deadline, args.poll, args.settle) and held
        except Stopped:
            pass
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        print(evaluate(args.report))
        if args.metrics:
            write_metrics(browser, session, args, cpu_before_page)
        if not args.then:
            take_screenshot(browser, session, args.screenshot)
        if args.requests:
            urls = [e["params"]["request"]["url"] for e in browser.events
                    if e.get("method") == "Network.requestWillBeSent"]
            urls = [u for u in urls if not u.startswith("data:")]  # decoded in place, not fetched
            with open(args.requests, "w") as f:
                f.write("".join(u + "\n" for u in urls))
    finally:
        browser.close()
        shutil.rmtree(profile, ignore_errors=True)
    if not held:
        print("page_probe: %r did not hold within %g s" % (args.then or args.until, args.timeout), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
