"""The drive's run-time engine, written once in C (``csrc/``), and its Python binding.

``csrc/include`` holds the contracts (the model, the profile, the solvers),
``csrc/src`` one C99 file per job, using libc and libm only. ``build.py``
compiles them into a plain shared library (no Python C API), ``library.py``
loads it with ctypes. cam.fmu's binary is compiled from the same files.
docs/architecture.md describes the layers.
"""
