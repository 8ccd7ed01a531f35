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
