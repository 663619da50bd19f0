"""FMI 3.0 Model Exchange (cam3.fmu) against FMI 2.0 Model Exchange (cam.fmu) in one host, fmpy's CVode.

Fig. 6 (u = 3.5 V, 2 s, 1 ms output, rtol 1e-9) through ``fmpy.simulate_fmu(fmi_type='ModelExchange')`` on both,
alternated per round: the wall time of each (best and median of the rounds), their ratio, the FMI calls each run
makes and whether the two results are the same bits (the same model functions and event update under both
versions' glue). Timings, not tests: tests/fmi3/test_fmi3_me.py checks the results.
"""
from __future__ import annotations

import json
import statistics
import sys
import time
from pathlib import Path

STOP, INTERVAL, RTOL = 2.0, 1e-3, 1e-9  # s, s, CVode's relative tolerance
START = {"u": 3.5}  # V: fig. 6


def measure(cam: Path, cam3: Path, rounds: int = 7) -> dict:
    """Wall times [s] of fmpy's Model Exchange run of fig. 6 on cam.fmu (FMI 2.0) and cam3.fmu (FMI 3.0), alternated;
    ``calls``: the FMI calls of one run of each; ``same_bits``: the outputs of the two are equal."""
    import fmpy
    import numpy as np

    fmus = {"fmi2": Path(cam), "fmi3": Path(cam3)}
    prepared = {k: (fmpy.extract(str(p)), fmpy.read_model_description(str(p))) for k, p in fmus.items()}
    kwargs = dict(fmi_type="ModelExchange", start_values=START, stop_time=STOP, output_interval=INTERVAL,
                  relative_tolerance=RTOL, solver="CVode")
    seconds: dict[str, list[float]] = {k: [] for k in fmus}
    results, calls = {}, {}
    for k, (folder, md) in prepared.items():  # once each untimed: loading the library, the first calls
        counted = [0]
        results[k] = fmpy.simulate_fmu(folder, model_description=md, fmi_call_logger=lambda _t: counted.__setitem__(
            0, counted[0] + 1), **kwargs)
        calls[k] = counted[0]
    for _ in range(rounds):
        for k, (folder, md) in prepared.items():
            t0 = time.perf_counter()
            fmpy.simulate_fmu(folder, model_description=md, **kwargs)
            seconds[k].append(time.perf_counter() - t0)
    names = [n for n in results["fmi2"].dtype.names if n != "time"]
    same = all(np.array_equal(results["fmi2"][n], results["fmi3"][n]) for n in names)
    best = {k: min(v) for k, v in seconds.items()}
    median = {k: statistics.median(v) for k, v in seconds.items()}
    return {"best_s": best, "median_s": median, "ratio_best": best["fmi3"] / best["fmi2"],
            "ratio_median": median["fmi3"] / median["fmi2"], "calls": calls, "same_bits": same, "rounds": rounds}


def run(ctx) -> int:
    """`cam-fmu bench fmi3_me`: the ratio FMI 3.0 / FMI 2.0 Model Exchange in fmpy (cam3.fmu built when stale)."""
    from ...fmu.build import ensure_fmu

    cam3 = ensure_fmu(None, log=ctx.say, model="cam3")
    r = measure(ctx.fmu, cam3, rounds=3 if ctx.quick else 7)
    ctx.say(f"# fmi3_me: fig. 6 through fmpy's CVode (rtol {RTOL:g}): FMI 2.0 ME {r['median_s']['fmi2'] * 1e3:.1f} ms, "
            f"FMI 3.0 ME {r['median_s']['fmi3'] * 1e3:.1f} ms (medians of {r['rounds']}): FMI 3.0 / FMI 2.0 = "
            f"{r['ratio_median']:.2f} (best {r['ratio_best']:.2f}); FMI calls {r['calls']['fmi2']} and "
            f"{r['calls']['fmi3']}; the outputs {'the same bits' if r['same_bits'] else 'NOT the same bits'}")
    (ctx.out / "fmi3_me.json").write_text(json.dumps(r, indent=1))
    return 0 if r["same_bits"] else 1


if __name__ == "__main__":  # python -m cam_fmu.tools.bench.fmi3_me CAM.FMU CAM3.FMU
    print(json.dumps(measure(Path(sys.argv[1]), Path(sys.argv[2])), indent=1))
