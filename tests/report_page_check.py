#!/usr/bin/python3
"""Checks a report that `depthbench report` wrote, the way a reader sees it.

  report_page_check.py schema REPORT_DIR SCHEMA
      results.json validates against the report's JSON Schema (jsonschema,
      Debian's python3-jsonschema), and the schema rejects a document with a
      field broken on purpose (so that the check itself can fail).

  report_page_check.py browser REPORT_DIR ARTIFACT_DIR
      opens report.html in headless Chromium (no network, fresh profile),
      waits for the page's own render check, and asserts: no console or
      page errors, every plot drawn with data in it, the headline table
      present; the bits-lost plots as small multiples (a panel per
      convention and format, every panel on the same y domain) with the
      theory lines; the speed/accuracy front per convention and format with
      interval bars and a cost axis that names its unit; the GPU-against-CPU
      differences in words when there are none; the findings by cause; the
      first screen wholly visible at 1024x768. Saves screenshots and the
      rendered DOM as test artifacts.
"""
import copy
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                  "--disable-component-update", "--no-first-run", "--disable-sync"]
# Virtual time lets the page finish its asynchronous drawing before the DOM
# is dumped; 60 s of it is far beyond what the page needs (about 2 s).
VIRTUAL_TIME_MS = "60000"
PLOTS = ["precision", "depth", "split", "diff", "speed", "trend"]


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def check_schema(report_dir, schema_path):
    import jsonschema
    with open(schema_path) as f:
        schema = json.load(f)
    with open(os.path.join(report_dir, "results.json")) as f:
        document = json.load(f)
    validator = jsonschema.Draft202012Validator(schema)
    errors = sorted(validator.iter_errors(document), key=lambda e: list(e.path))
    for e in errors[:10]:
        print("schema error at /%s: %s" % ("/".join(map(str, e.path)), e.message))
    if errors:
        fail("%d schema errors in results.json" % len(errors))
    # The schema must be able to say no: a bits figure as text, a missing
    # section, an unknown level, a device field it does not name (the
    # device is written from the results' field list: the schema must keep
    # up with it).
    for name, broken in [("bits as text", lambda d: d["split"][0].__setitem__("total", "12")),
                         ("no headline", lambda d: d.pop("headline")),
                         ("unknown level", lambda d: d["precision_points"][0].__setitem__("level", "p42")),
                         ("an unnamed device field",
                          lambda d: d["environment"]["backends"][0]["device"].__setitem__("memory", "80 GB"))]:
        d = copy.deepcopy(document)
        broken(d)
        if validator.is_valid(d):
            fail("the schema accepts a document with " + name)
    # A report run without --speed costs nothing from a device it did not
    # run on: every speed file it used was measured on one of its backends'
    # devices, and so was every measured cost the front shows.
    devices = {b["device"]["name"] for b in document["environment"]["backends"]}
    for path in document["environment"]["speed_files"]:
        with open(path) as f:
            made_on = json.load(f)["run"]["device"]["name"]
        if made_on not in devices:
            fail("the report used %s, measured on %r, a device it did not run on (%s)" % (path, made_on, sorted(devices)))
    for source in document["speed"]["sources"]:
        if source["device"] and source["device"] not in devices:
            fail("the front shows costs measured on %r, a device the report did not run on" % source["device"])
    print("results.json: valid (%d headline rows, %d precision points)" %
          (len(document["headline"]), len(document["precision_points"])))


def check_browser(report_dir, artifact_dir):
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        fail("chromium is not installed (./setup.sh --tests installs it)")
    os.makedirs(artifact_dir, exist_ok=True)
    page = "file://" + os.path.abspath(os.path.join(report_dir, "report.html"))
    with tempfile.TemporaryDirectory() as profile:
        common = [chromium] + CHROMIUM_FLAGS + ["--user-data-dir=" + profile, "--virtual-time-budget=" + VIRTUAL_TIME_MS]
        dom = subprocess.run(common + ["--enable-logging=stderr", "--v=0", "--dump-dom", page],
                             capture_output=True, text=True, timeout=300)
        if dom.returncode != 0:
            fail("chromium exited with %d: %s" % (dom.returncode, dom.stderr[-2000:]))
        with open(os.path.join(artifact_dir, "report.dom.html"), "w") as f:
            f.write(dom.stdout)
        shot = os.path.join(artifact_dir, "report.png")
        subprocess.run(common + ["--hide-scrollbars", "--window-size=1300,6000", "--screenshot=" + shot, page],
                       capture_output=True, text=True, timeout=300)
    # Console messages that are errors (Chromium logs the page's console on stderr).
    console_errors = [line for line in dom.stderr.splitlines()
                      if "CONSOLE" in line and re.search(r"error|uncaught|exception", line, re.I)]
    if console_errors:
        fail("console errors:\n" + "\n".join(console_errors[:10]))
    match = re.search(r'<pre id="render-check"[^>]*data-done="true"[^>]*>(.*?)</pre>', dom.stdout, re.S)
    if not match:
        fail("the page did not finish drawing (no render check in the DOM)")
    check = json.loads(match.group(1).replace("&quot;", '"').replace("&amp;", "&"))
    if check["errors"]:
        fail("page errors: %s" % check["errors"])
    if check["headline_rows"] < 1:
        fail("the headline table is empty")
    for plot in PLOTS:
        drawn = check["plots"].get(plot)
        if drawn is None or drawn < 1:
            fail("plot '%s' drew %s data marks" % (plot, drawn))
    if not os.path.isfile(shot) or os.path.getsize(shot) < 10000:
        fail("no screenshot")
    with open(os.path.join(report_dir, "results.json")) as f:
        document = json.load(f)
    check_small_multiples(check, document)
    check_differences_and_findings(check, document)
    if check.get("split_parts") != ["arith", "production", "storage"]:
        fail("the chart of error parts draws %s, not the three parts (production, storage, arith)" %
             check.get("split_parts"))
    check_first_screen(page, artifact_dir, chromium, document)
    if document.get("scene") is not None:
        check_scene_chart(check, document["scene"])
        if document["scene"].get("capture") is not None:
            check_capture_picture(check, report_dir, document["scene"]["capture"])
    print("report.html: %d headline rows; data marks per plot: %s; screenshot %s" %
          (check["headline_rows"], check["plots"], shot))


def check_shared_y(name, plot, panels):
    if plot is None:
        fail("no small-multiple check for the %s plot" % name)
    if plot["panels"] != panels:
        fail("the %s plot has %d panels, not one per convention and format (%d)" % (name, plot["panels"], panels))
    domains = {json.dumps(d) for d in plot["y_domains"]}
    if len(domains) != 1 or None in plot["y_domains"]:
        fail("the %s plot's panels are not on one y domain: %s" % (name, sorted(domains)))


# The theory lines a panel of each format draws beside the float32 floor
# and, for every convention but linear, the one-bit-per-doubling line.
STORAGE_BOUNDS = {"d16_unorm": "16-bit unorm storage bound", "r16_unorm": "16-bit unorm storage bound",
                  "x8_d24_unorm": "24-bit unorm storage bound", "r16_sfloat": "fp16 storage bound"}


def check_small_multiples(check, document):
    """Bits lost against far/near: a panel per convention and format (an
    infinite-far convention in its finite twin's), one y domain, the theory
    lines; the front: a panel per convention and format, one y domain,
    interval bars, its cost unit named."""
    points = document["precision_points"]
    encodings = {(p["convention"].replace("-inf", ""), p["format"]) for p in points}
    precision = check.get("precision")
    check_shared_y("precision", precision, len(encodings))
    expected = {"float32 floor (24-bit mantissa)"} | {STORAGE_BOUNDS[f] for _, f in encodings if f in STORAGE_BOUNDS}
    if any(c != "linear" for c, _ in encodings):
        expected.add("standard Z: 1 bit lost per doubling of far/near")
    missing = expected - set(precision["theory"])
    if missing:
        fail("theory lines missing from the precision plot: %s (drawn: %s)" % (sorted(missing), precision["theory"]))
    rows = document["speed"]["rows"]
    if not rows:
        return
    best = next(s for s in document["speed"]["sources"] if any(r["source"] == s["source"] for r in rows))
    speed = check.get("speed")
    check_shared_y("speed", speed, len({(r["convention"], r["format"]) for r in rows if r["source"] == best["source"]}))
    if speed["intervals"] < 1:
        fail("the speed/accuracy front draws no accuracy intervals")
    if best["cost_title"] not in speed["titles"] or not re.search(r"\(µs\) on |static cost", best["cost_title"]):
        fail("the front's cost axis does not name its unit: titles %s, expected %r" % (speed["titles"], best["cost_title"]))
    print("small multiples: %d bits-lost panels on y %s with %s; %d front panels, %d interval bars, cost axis %r" %
          (precision["panels"], precision["y_domains"][0], sorted(precision["theory"]), speed["panels"],
           speed["intervals"], best["cost_title"]))


def check_differences_and_findings(check, document):
    d = document["backend_differences"]
    if len(d["backends"]) == 2 and not d["rows"] and "No cell differs" not in check["diff_text"]:
        fail("no GPU-against-CPU difference, and the page does not say so: %r" % check["diff_text"])
    if d["rows"] and "No cell differs" in check["diff_text"]:
        fail("the page says no cell differs, but %d do" % len(d["rows"]))
    groups = document["findings"]["groups"]
    if check["finding_groups"] != max(1, len(groups)):
        fail("the page lists %d finding groups, the document has %d" % (check["finding_groups"], len(groups)))
    print("GPU against CPU: %r; findings: %d causes" % (check["diff_text"][:80], len(groups)))


def check_first_screen(page, artifact_dir, chromium, document):
    """At 1024x768 the first-screen table is wholly visible: the lever
    table, a row per convention and format with the budget, world-unit,
    bytes and cost columns before the variant; a row that keeps nothing
    says "do not use", never a variant; its screenshot is saved
    (docs/report-first-screen.png is one)."""
    with tempfile.TemporaryDirectory() as profile:
        common = [chromium] + CHROMIUM_FLAGS + ["--user-data-dir=" + profile, "--virtual-time-budget=" + VIRTUAL_TIME_MS,
                                                "--window-size=1024,768", "--hide-scrollbars"]
        dom = subprocess.run(common + ["--dump-dom", page], capture_output=True, text=True, timeout=300)
        shot = os.path.join(artifact_dir, "report-first-screen.png")
        subprocess.run(common + ["--screenshot=" + shot, page], capture_output=True, text=True, timeout=300)
    match = re.search(r'<pre id="render-check"[^>]*data-done="true"[^>]*>(.*?)</pre>', dom.stdout, re.S)
    if not match:
        fail("the page did not finish drawing at 1024x768")
    first = json.loads(match.group(1).replace("&quot;", '"').replace("&amp;", "&")).get("first_screen")
    if not first:
        fail("no first-screen table")
    # Headless Chromium gives a 1024x768 window a viewport a little shorter
    # than 768 (625 here): visible there is visible at 768.
    if first["window"][0] != 1024 or first["window"][1] > 768:
        fail("the viewport is %s, not within 1024x768" % first["window"])
    if first["rows"] < 1:
        fail("the first-screen table is empty")
    for column in ["use", "cost", "f/n for 1e-3", "f/n for 1e-6", "far at 100 m", "at 10 km", "B/px"]:
        if column not in first["columns"]:
            fail("the first-screen table has no '%s' column: %s" % (column, first["columns"]))
    if first["columns"][-1] != "use":
        fail("the variant comes before the lever: columns %s" % first["columns"])
    use = first["columns"].index("use")
    recommendations = document["recommendations"]
    if len(first["cells"]) != len(recommendations):
        fail("the first screen shows %d rows, the document has %d" % (len(first["cells"]), len(recommendations)))
    kept = [r["bits"] if r["bits"] is not None else 99 for r in recommendations]
    if kept != sorted(kept):
        fail("the first screen does not lead with the combinations that keep the most bits: %s" % kept)
    nothing = 0
    for row, cells in zip(recommendations, first["cells"]):
        low = row["bits_low"] if row["bits_low"] is not None else row["bits"]
        if low is not None and low >= 23.0 and cells[use] != "do not use":
            fail("%s/%s keeps nothing (%.1f bits lost at least) yet says %r" %
                 (row["convention"], row["format"], low, cells[use]))
        if row["keeps_nothing"]:
            nothing += 1
            if cells[use] != "do not use":
                fail("%s/%s: 'do not use' expected, the page says %r" % (row["convention"], row["format"], cells[use]))
        metres = cells[first["columns"].index("far at 100 m")]
        if row["bits"] is not None and not re.fullmatch(r"[0-9.e-]+ (mm|cm|m|km)", metres):
            fail("%s/%s: no world units at 100 m: %r" % (row["convention"], row["format"], metres))
    print("first screen: %d 'do not use' rows, world units such as %r" %
          (nothing, first["cells"][0][first["columns"].index("far at 100 m")]))
    scene = document.get("scene")
    if scene is not None:
        check_scene_screen(first, scene)
    elif not first["visible"]:
        fail("the first-screen table is not wholly visible at 1024x768: it ends at x %d, y %d" %
             (first["right"], first["bottom"]))
    print("first screen at 1024x768: %d rows, columns %s, ends at y %d" % (first["rows"], first["columns"], first["bottom"]))


def check_scene_chart(check, scene):
    """The scene's chart draws every candidate's error against eye depth
    that the document holds, and the requirement's rule."""
    points = sum(1 for r in scene["rows"] for p in r["by_depth"] if p["value"] is not None and p["value"] > 0)
    if points == 0:
        fail("the scene has no error against eye depth to draw")
    drawn = check["plots"].get("scene")
    if drawn is None or drawn < points:
        fail("the scene chart drew %s data marks for %d points" % (drawn, points))
    if check.get("scene_requirement", 0) < 1:
        fail("the scene chart does not draw the requirement")
    print("scene chart: %d points, %d requirement rules" % (points, check["scene_requirement"]))


def check_capture_picture(check, report_dir, capture):
    """A captured frame's bits lost per pixel: the PNG beside the page is
    the one the page shows, decoded at its own size and drawn."""
    path = os.path.join(report_dir, capture["image"])
    with open(path, "rb") as f:
        header = f.read(24)
    if header[:8] != b"\x89PNG\r\n\x1a\n":
        fail("%s is not a PNG" % path)
    width, height = int.from_bytes(header[16:20], "big"), int.from_bytes(header[20:24], "big")
    shown = check.get("capture_image")
    if shown is None:
        fail("the page does not show the capture's picture")
    if (shown["width"], shown["height"]) != (width, height):
        fail("the page decoded the picture at %dx%d, the file is %dx%d" % (shown["width"], shown["height"], width,
                                                                          height))
    if shown["shown"] < width:
        fail("the picture is drawn %d pixels wide, narrower than the frame (%d)" % (shown["shown"], width))
    print("capture picture: %dx%d, drawn %d wide; %s by %s: median %.1f, p99.9 %.1f, worst %.1f bits" %
          (width, height, shown["shown"], capture["source"], capture["cell"], capture["median_bits"],
           capture["p999_bits"], capture["worst_bits"]))


def check_scene_screen(first, scene):
    """A scene report opens on the scene's table, wholly visible at
    1024x768: a row per convention and format of its engine, the measured
    error in the requirement's unit, and "do not use" where the
    requirement is not met, the variant where it is."""
    page = first.get("scene")
    if not page:
        fail("the report has a scene, the page shows no scene table")
    if page["bottom"] > first["window"][1]:
        fail("the scene table is not wholly visible at 1024x768: it ends at y %d" % page["bottom"])
    if len(page["cells"]) != len(scene["rows"]) or not scene["rows"]:
        fail("the scene table shows %d rows, the document has %d" % (len(page["cells"]), len(scene["rows"])))
    use = page["columns"].index("use")
    measured = page["columns"].index("measured (upper)")
    refused = 0
    for row, cells in zip(scene["rows"], page["cells"]):
        if row["meets"] and cells[use] != row["variant"]:
            fail("%s/%s meets the requirement, the page says %r" % (row["convention"], row["format"], cells[use]))
        if not row["meets"]:
            refused += 1
            if not cells[use].startswith("do not use"):
                fail("%s/%s fails the requirement, the page says %r" % (row["convention"], row["format"], cells[use]))
        if row["measured"] is not None and not re.fullmatch(r"[0-9.e-]+", cells[measured]):
            fail("%s/%s: no measured figure: %r" % (row["convention"], row["format"], cells[measured]))
    print("scene %r (%s): %d rows, %d 'do not use'" % (scene["name"], scene["requirement"], len(scene["rows"]), refused))


if __name__ == "__main__":
    if len(sys.argv) != 4 or sys.argv[1] not in ("schema", "browser"):
        print(__doc__)
        sys.exit(2)
    if sys.argv[1] == "schema":
        check_schema(sys.argv[2], sys.argv[3])
    else:
        check_browser(sys.argv[2], sys.argv[3])
