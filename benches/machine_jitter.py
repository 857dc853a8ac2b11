"""How much this machine delays a fixed piece of work: runs a ~3.5 ms pure-Python loop 1,500
times and prints the median, p99 and maximum of its wall time and of the thread's CPU time. On a
shared VM the maximum shows stalls (steal time) that also land in any single-scan timing, such as
the SLAM example's "max per scan"; when the thread's CPU clock shows them too, a CPU-time
measurement cannot separate them from real work either.

python3 benches/machine_jitter.py
"""

import time


def work():
    s = 0
    for i in range(60000):
        s += i * i
    return s


wall, cpu = [], []
for _ in range(1500):
    start, start_cpu = time.perf_counter(), time.thread_time()
    work()
    cpu.append((time.thread_time() - start_cpu) * 1e3)
    wall.append((time.perf_counter() - start) * 1e3)
for name, times in (("wall", wall), ("thread CPU", cpu)):
    times.sort()
    print(f"fixed work, {name}: median {times[len(times) // 2]:.2f} ms, "
          f"p99 {times[int(len(times) * 0.99)]:.2f} ms, max {times[-1]:.2f} ms")
