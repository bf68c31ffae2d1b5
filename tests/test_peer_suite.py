#!/usr/bin/env python3
"""Self-test of tools/peer_suite.py's arithmetic and page (stdlib unittest; runs with plain
python3, no renderer run): the times to the targets and the marginal cost of a sample from a
sweep's runs, the ratio to the fastest peer, entries kept between runs and the notes kept when
the page is regenerated.

    python3 tests/test_peer_suite.py
"""

import json
import math
import os
import sys
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPO, "tools"))

import peer_suite as ps  # noqa: E402


def sweep(renderer, seconds, rel_mse, spps=(4, 16, 64, 256)):
    return [{"renderer": renderer, "spp": n, "seconds": t, "rel_mse": e, "mean_ratio": 1.0}
            for n, t, e in zip(spps, seconds, rel_mse)]


class Summary(unittest.TestCase):
    def test_targets_and_cost(self):
        # relMSE 0.1 at 1 s, 0.01 at 10 s: on log-log the line through them reaches 1e-2 at
        # 10 s exactly and 3.16e-2 at sqrt(10) s; 1e-3 lies past the last run (relMSE 1e-3 at
        # 40 s, reached there).
        rows = sweep("wavepath", (1.0, 10.0, 20.0, 40.0), (0.1, 0.01, 0.004, 0.001))
        s = ps.summarize(rows, 512, 512)["wavepath"]
        self.assertAlmostEqual(s["targets"][0][0], 10.0)
        self.assertAlmostEqual(s["targets"][1][0], 40.0)
        # Marginal cost: (40 - 20) s over (256 - 64) spp x 512^2 pixels.
        self.assertAlmostEqual(s["ns_per_sample"], 1e9 * 20.0 / (192 * 512 * 512))

    def test_extrapolated_past_the_last_run(self):
        rows = sweep("mitsuba", (1.0, 2.0, 4.0, 8.0), (0.1, 0.04, 0.02, 0.01))
        t, mark = ps.summarize(rows, 64, 64)["mitsuba"]["targets"][1]
        self.assertEqual(mark, "~")
        self.assertAlmostEqual(t, 8.0 * 0.01 / 1e-3)  # relMSE ~ 1/time from the last run

    def test_noise_gives_no_cost(self):
        rows = sweep("cycles", (1.0, 1.1, 1.3, 1.2), (0.1, 0.03, 0.01, 0.003))
        self.assertIsNone(ps.summarize(rows, 64, 64)["cycles"]["ns_per_sample"])


class Page(unittest.TestCase):
    def entry(self, work, scene, size, rows):
        name = ps.entry_key(scene, size)
        os.makedirs(os.path.join(work, name))
        with open(os.path.join(work, name, "entry.json"), "w") as f:
            json.dump({"scene": scene, "width": size[0], "height": size[1], "commit": "abc1234",
                       "date": "2026-12-08", "renderers": ["wavepath", "mitsuba"],
                       "summary": ps.summarize(rows, *size), "rows": rows}, f)

    def test_rows_ratio_missing_and_notes(self):
        with tempfile.TemporaryDirectory() as tmp:
            work, out = os.path.join(tmp, "work"), os.path.join(tmp, "docs", "suite.md")
            # wavepath reaches 1e-2 at 10 s, Mitsuba at 20 s, its ldsampler at 40 s: the
            # fastest peer is Mitsuba, ratio 0.5.
            e = (0.1, 0.01, 0.004, 0.001)
            rows = (sweep("wavepath", (1.0, 10.0, 20.0, 40.0), e)
                    + sweep("mitsuba", (2.0, 20.0, 40.0, 80.0), e)
                    + sweep("mitsuba-ld", (4.0, 40.0, 80.0, 160.0), e))
            self.entry(work, "DamagedHelmet", (512, 512), rows)
            a = ps.parse_args(["--work", work, "--out", out, "--page-only"])
            ps.write_page(a, ps.load_entries(a))
            with open(out) as f:
                page = f.read()
            line = next(x for x in page.splitlines() if x.startswith("| [DamagedHelmet]"))
            cells = [c.strip() for c in line.split("|")[1:-1]]
            self.assertEqual(cells[1], "0.01")
            self.assertEqual(cells[2:5], ["10 s", "20 s", "40 s"])
            self.assertEqual(cells[5], "not run")  # Cycles
            self.assertEqual(cells[6], "0.50")
            self.assertIn("peers_suite/DamagedHelmet_512x512.md", cells[0])
            self.assertIn("Not measured yet: cornell_box, FlightHelmet", page)
            self.assertIn("--sizes 1280x720", page)
            # Hand-written notes after the mark survive a regeneration.
            with open(out, "a") as f:
                f.write("A note.\n")
            ps.write_page(a, ps.load_entries(a))
            with open(out) as f:
                self.assertTrue(f.read().endswith(ps.peers.NOTES_MARK + "\nA note.\n"))


class Arguments(unittest.TestCase):
    def test_refusals(self):
        for argv in (["--scenes", "Sponza"], ["--sizes", "512"], ["--renderers", "mitsuba"],
                     ["--renderers", "wavepath,pbrt"]):
            with self.assertRaises(SystemExit) as e:
                ps.parse_args(argv)
            self.assertEqual(e.exception.code, 2, argv)

    def test_sizes(self):
        a = ps.parse_args(["--sizes", "1280x720"])
        self.assertEqual(a.sizes, [(1280, 720)])
        self.assertTrue(math.isclose(1280 / 720, 16 / 9))


if __name__ == "__main__":
    unittest.main()
