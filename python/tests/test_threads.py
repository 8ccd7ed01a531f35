# SPDX-License-Identifier: BSD-2-Clause
"""Two runs in two threads (the GIL is released while the engine runs): the same results as one after the other.
The speed-up itself is measured by bench/python_bench.py (docs/performance.md), not asserted here."""
import threading

import numpy as np

import pednav


def test_two_threads_equal_serial(forest, square, forest_result):
    serial_square = pednav.run(square["config"], mode="tc")
    results = {}

    def work(name, config):
        results[name] = pednav.run(config, mode="tc")

    threads = [threading.Thread(target=work, args=("forest", forest["config"])),
               threading.Thread(target=work, args=("square", square["config"]))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for name, serial in [("forest", forest_result), ("square", serial_square)]:
        for which in ["forward", "smoothed"]:
            a, b = getattr(results[name], which), getattr(serial, which)
            for k in a:
                np.testing.assert_array_equal(a[k], b[k], err_msg=f"{name} {which} {k}")


def test_python_runs_while_the_engine_runs(forest):
    # With the GIL held by the engine this loop would stand still between the progress calls (the engine's hook takes
    # the GIL for a moment every 50 ms at most); released, it keeps counting all along.
    started = threading.Event()
    progress = []

    def on_progress(f):
        progress.append(f)
        started.set()

    worker = threading.Thread(target=pednav.run, args=(forest["config"],),
                              kwargs={"mode": "tc", "progress": on_progress})
    worker.start()
    started.wait()
    calls_at_start = len(progress)
    count = 0
    while worker.is_alive():
        count += 1
    worker.join()
    assert len(progress) > calls_at_start + 2  # the engine ran for several hook periods while this loop counted
    # Measured ~10^6 iterations per engine second on the shared 2-core VM; 10^4 is far from a held GIL's ~0.
    assert count > 10_000
