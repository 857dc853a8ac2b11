"""How much this machine delays a fixed piece of work: runs a ~3 ms pure-Python loop 1,500
times and prints the median, p99 and maximum. On a shared VM the maximum shows preemptions
(steal time) that also land in any single-scan timing, such as the SLAM example's "max per scan".

python3 benches/machine_jitter.py
"""

import time


def work():
    s = 0
    for i in range(60000):
        s += i * i
    return s


times = []
for _ in range(1500):
    start = time.perf_counter()
    work()
    times.append((time.perf_counter() - start) * 1e3)
times.sort()
print(f"fixed work: median {times[len(times) // 2]:.2f} ms, p99 {times[int(len(times) * 0.99)]:.2f} ms, "
      f"max {times[-1]:.2f} ms")
