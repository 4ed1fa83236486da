"""The speed of this (shared, virtual) machine now: the wall time of a pure-Python loop of
10^7 additions at a module's top level, in seconds.

    python scripts/machine_speed.py

The timings in docs/ quote it beside their numbers (docs/performance.md says what it
takes when the machine runs fast). Run inside a function, where names are local, the same loop is
faster: compare only like with like.
"""

import time

clock = time.perf_counter()
total = 0
for i in range(10_000_000):
    total += i
print(f"{time.perf_counter() - clock:.3f}")
