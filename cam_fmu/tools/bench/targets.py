"""The former command ``python -m cam_fmu.tools.bench.targets [cam.fmu]``: it is ``cam-fmu bench loops``."""
if __name__ == "__main__":
    import sys
    from pathlib import Path

    from . import run

    print("python -m cam_fmu.tools.bench.targets is deprecated: use cam-fmu bench loops [--fmu FILE]",
          file=sys.stderr)
    sys.exit(run(["loops"], Path("out") / "bench", fmu_path=Path(sys.argv[1]) if len(sys.argv) > 1 else None))
