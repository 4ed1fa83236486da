"""The report page of a small sweep rendered in headless Chromium (Debian's ``chromium``
package, which scripts/test.sh installs; elsewhere the test is skipped, saying so, where
it is not installed, but fails under CI, where a skip would hide a missing install): the page loads without a script or resource error, every figure is drawn
(its PNG decoded) at a readable size, and the page and its tables fit a 1400 px window,
with the folded parts closed and open. The measures are taken by a script added to a
copy of the page and read back from the DOM Chromium dumps (no driver needed)."""

import json
import os
import re
import shutil
import subprocess

import pytest

from helpers import describe
from test_sweep_cli import RISER, OFFSETS, run_module

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
WIDTH = 1400
# What the page's script measures once it has loaded, as JSON in <pre id="measure">;
# OPEN opens every <details> first.
MEASURE = """<script>
window.__errors = [];
window.addEventListener("error", e => window.__errors.push(String(e.message || e.type)),
                        true);
window.addEventListener("load", () => {
  if (OPEN) document.querySelectorAll("details").forEach(d => d.open = true);
  const box = e => e.getBoundingClientRect();
  const shown = e => !e.closest("details:not([open])");
  const out = {width: window.innerWidth, scroll: document.documentElement.scrollWidth,
    errors: window.__errors,
    tables: [...document.querySelectorAll("table")].filter(shown).map(t => ({
      id: t.id, right: box(t).right,
      boxRight: box(t.closest(".scroll") || t).right})),
    images: [...document.images].map(i => ({alt: i.alt,
      ok: i.complete && i.naturalWidth > 0, width: box(i).width}))};
  const pre = document.createElement("pre");
  pre.id = "measure";
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});
</script>"""

if CHROMIUM is None and os.environ.get("CI"):
    raise RuntimeError("headless Chromium is missing under CI: scripts/test.sh installs "
                       "Debian's chromium")
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason=(
    "headless Chromium is not installed (Debian: apt-get install chromium); the report "
    "page's browser check needs it"))


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    """The report of the 3-case offset sweep: its path."""
    folder = tmp_path_factory.mktemp("browser")
    process = run_module("petsc_rod.sweep", RISER + OFFSETS + ["-sweep_output",
                                                               str(folder / "sweep")])
    assert process.returncode == 0, describe(process)
    output = folder / "report.html"
    process = run_module("petsc_rod.report", [str(folder / "sweep"), "-o", str(output),
                                              "--min-bend-radius", "150"])
    assert process.returncode == 0, describe(process)
    return output


def measure(path, opened):
    """What MEASURE finds in the page at ``path`` in a WIDTH px window (details opened
    when ``opened``)."""
    copy = path.with_name(f"measured_{int(opened)}.html")
    script = MEASURE.replace("OPEN", "true" if opened else "false")
    copy.write_text(path.read_text().replace("</body>", script + "</body>"))
    done = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu",
                           f"--window-size={WIDTH},1000", "--virtual-time-budget=10000",
                           "--dump-dom", copy.as_uri()],
                          capture_output=True, text=True, timeout=120, check=False)
    found = re.search(r'<pre id="measure">(.*?)</pre>', done.stdout, re.S)
    assert found, (done.returncode, done.stderr[-2000:])
    return json.loads(found.group(1).replace("&quot;", '"').replace("&amp;", "&"))


@pytest.mark.parametrize("opened", [False, True])
def test_the_report_loads_and_fits_a_1400_px_window(page, opened):
    numbers = measure(page, opened)
    assert numbers["width"] == WIDTH
    assert numbers["errors"] == []
    assert numbers["scroll"] <= WIDTH, numbers["scroll"]          # no sideways scroll
    ids = [table["id"] for table in numbers["tables"]]
    assert {"inputs", "results", "regions"} <= set(ids)
    assert ("summary" in ids) == opened and ("line_types" not in ids)
    for table in numbers["tables"]:
        # a table fits, or scrolls inside a box that fits (the wide SI summary)
        assert table["boxRight"] <= WIDTH, table
        if table["id"] != "summary":
            assert table["right"] <= WIDTH, table
    images = numbers["images"]
    assert len(images) == 1 + 6 + 3 and all(image["ok"] for image in images), images
    for image in images:
        readable = 600 if image["alt"].startswith("range graph") else 1000
        assert readable <= image["width"] <= WIDTH, image


@pytest.fixture(scope="module")
def system_page(tmp_path_factory):
    """The report of the small spread's system file with a watch circle of 3 headings:
    its path."""
    from helpers import run_petsc_rod
    from test_system_cli import DECK
    folder = tmp_path_factory.mktemp("system")
    result = folder / "system.h5"
    process = run_petsc_rod(["-rod_system", DECK, "-rod_system_watch_circle", "Body1,2e4,3",
                             "-rod_output", str(result)], 1, 300)
    assert process.returncode == 0, describe(process)
    output = folder / "system.html"
    process = run_module("petsc_rod.report", [str(result), "-o", str(output)])
    assert process.returncode == 0, describe(process)
    return output


def test_a_system_report_loads_and_fits_a_1400_px_window(system_page):
    numbers = measure(system_page, True)
    assert numbers["errors"] == [] and numbers["scroll"] <= WIDTH, numbers["scroll"]
    ids = {table["id"] for table in numbers["tables"]}
    assert {"bodies", "points", "lines", "stiffness_Body1", "watch_circle"} <= ids
    assert all(table["boxRight"] <= WIDTH for table in numbers["tables"])
    images = numbers["images"]
    assert [image["alt"] for image in images] == ["plan and elevation", "watch circle",
                                                  "line Line1", "line Line2", "line Line3"]
    assert all(image["ok"] and 1000 <= image["width"] <= WIDTH for image in images), images
