"""The speed of this (shared, virtual) machine now: the wall time of a pure-Python loop of
10^7 additions at a module's top level, in seconds.

    python scripts/machine_speed.py

The timings in docs/ quote it beside their numbers: on the 2-core machine they were
measured on, it took 0.62-0.70 s when the machine ran fast and up to 1.7 s when other
jobs loaded it. (Run inside a function, where names are local, the same loop takes
about 2.3 times less: compare only like with like.)
"""

import time

clock = time.perf_counter()
total = 0
for i in range(10_000_000):
    total += i
print(f"{time.perf_counter() - clock:.3f}")
