"""estimate() releases the GIL: a Python thread keeps running while the filter works."""

import threading
import time

import posefilter as pf


def test_thread_makes_progress_during_estimate(easy_scene):
    s = easy_scene
    depth, camera, mesh, prior = s.depth, s.camera, s.target, s.prior
    # Long enough to tell on a fast machine (≈ 0.3 s with AVX-512 on one core): every iteration
    # runs (no confidence or stall stop).
    est = pf.Estimator(particles=510, iterations=12, restarts=1, polish_steps=0, threads=1, confidence=1.0,
                       stall_iterations=0)
    ticks = []
    stop = threading.Event()

    def counter():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)  # sleep releases the GIL too; the point is that we get it back

    thread = threading.Thread(target=counter)
    thread.start()
    try:
        t0 = time.perf_counter()
        est.estimate(depth, camera, mesh, prior)
        t1 = time.perf_counter()
    finally:
        stop.set()
        thread.join()
    # Ticks strictly inside the middle half of the call: with the GIL held for the whole call
    # there would be none at all (the counter cannot run Python code without it).
    lo, hi = t0 + 0.25 * (t1 - t0), t0 + 0.75 * (t1 - t0)
    inside = [t for t in ticks if lo < t < hi]
    assert t1 - t0 > 0.05, "estimate too short to tell"
    assert len(inside) >= 3, (len(inside), t1 - t0)
