"""Dask distributed against Ray for mechbook's batches, on this machine (a local cluster).

    python bench/schedulers.py [--problems ID ...] [--workers 2] [--only dask|ray]

For each scheduler that is installed (mechbook depends on neither; `pip install
"dask[distributed]" ray` in a scratch environment to compare): the time until a local
cluster of WORKERS single-threaded workers is ready, the memory of every process it
started, the round trip of 200 empty tasks, `mechbook check` of a few problems through
it (the same task both ways: a one-worker local batch inside the task, so the time and
memory limits act from outside, as in the local pool) against the local pool, and how
long a task running past a 3 s limit takes to come back as an error (our limit inside
the task; and, for Ray, its own `ray.cancel(force=True)`). Prints one table.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mechbook.app.running.batch import Batch, BatchOptions  # noqa: E402
from mechbook.app.running.distributed import check_task, limited, tree_files  # noqa: E402

PROBLEMS = ["lim-2031", "lim-2036", "lim-2043", "symon-09-11"]


def _descendants(pid: int) -> list[int]:
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as fh:
                ppid = int(fh.read().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            continue
        children.setdefault(ppid, []).append(int(entry))
    out, todo = [], [pid]
    while todo:
        p = todo.pop()
        for c in children.get(p, []):
            out.append(c)
            todo.append(c)
    return out


def _rss_mb(pids: list[int]) -> float:
    total = 0.0
    for p in pids:
        try:
            with open(f"/proc/{p}/statm") as fh:
                total += int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20
        except (OSError, ValueError, IndexError):
            pass
    return total


def _noop(i):
    return i


def _sleepy(seconds):
    time.sleep(seconds)
    return seconds


def _limited_sleep(seconds, limit):
    try:
        return limited(time.sleep, (seconds,), limit, 0)
    except Exception as exc:  # noqa: BLE001 - reported as the measurement
        return f"stopped: {exc}"


def bench_dask(workers: int, problems: list[str], options: BatchOptions) -> dict:
    from dask.distributed import Client

    from mechbook.app.running.distributed import local_cluster

    row = {"scheduler": "dask"}
    t = time.perf_counter()
    cluster = local_cluster(workers)
    client = Client(cluster)
    client.wait_for_workers(workers)
    row["start_s"] = time.perf_counter() - t
    try:
        row["rss_mb"] = _rss_mb([os.getpid(), *_descendants(os.getpid())])
        t = time.perf_counter()
        client.gather([client.submit(_noop, i, pure=False) for i in range(200)])
        row["task_ms"] = (time.perf_counter() - t) / 200 * 1e3
        t = time.perf_counter()
        runs = client.gather([client.submit(check_task, pid, tree_files(pid, ROOT), options,
                                            str(ROOT), pure=False, priority=len(problems) - i)
                              for i, pid in enumerate(problems)])
        row["check_s"] = time.perf_counter() - t
        row["check_ok"] = all(not r.error for r in runs)
        row["rss_busy_mb"] = _rss_mb([os.getpid(), *_descendants(os.getpid())])
        t = time.perf_counter()
        msg = client.submit(_limited_sleep, 60, 3.0, pure=False).result()
        row["limit_s"] = time.perf_counter() - t
        row["limit"] = msg
        t = time.perf_counter()
        client.submit(_noop, 1, pure=False).result()
        row["after_limit_ms"] = (time.perf_counter() - t) * 1e3
    finally:
        client.close()
        cluster.close()
    return row


def bench_ray(workers: int, problems: list[str], options: BatchOptions) -> dict:
    import ray

    row = {"scheduler": "ray"}
    t = time.perf_counter()
    ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False,
             runtime_env={"env_vars": {"PYTHONPATH": str(ROOT)}})
    noop = ray.remote(num_cpus=1)(_noop)
    ray.get([noop.remote(i) for i in range(workers)])  # workers up
    row["start_s"] = time.perf_counter() - t
    try:
        row["rss_mb"] = _rss_mb([os.getpid(), *_descendants(os.getpid())])
        t = time.perf_counter()
        ray.get([noop.remote(i) for i in range(200)])
        row["task_ms"] = (time.perf_counter() - t) / 200 * 1e3
        check = ray.remote(num_cpus=1)(check_task)
        t = time.perf_counter()
        runs = ray.get([check.remote(pid, tree_files(pid, ROOT), options, str(ROOT))
                        for pid in problems])
        row["check_s"] = time.perf_counter() - t
        row["check_ok"] = all(not r.error for r in runs)
        row["rss_busy_mb"] = _rss_mb([os.getpid(), *_descendants(os.getpid())])
        t = time.perf_counter()
        row["limit"] = ray.get(ray.remote(num_cpus=1)(_limited_sleep).remote(60, 3.0))
        row["limit_s"] = time.perf_counter() - t
        sleepy = ray.remote(num_cpus=1, max_retries=0)(_sleepy)
        t = time.perf_counter()
        ref = sleepy.remote(60)
        ready, _ = ray.wait([ref], timeout=3.0)
        if not ready:
            ray.cancel(ref, force=True)
        try:
            ray.get(ref)
        except Exception as exc:  # noqa: BLE001 - the measurement
            row["ray_cancel"] = type(exc).__name__
        row["ray_cancel_s"] = time.perf_counter() - t
        t = time.perf_counter()
        ray.get(noop.remote(1))
        row["after_limit_ms"] = (time.perf_counter() - t) * 1e3
    finally:
        ray.shutdown()
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--problems", nargs="*", default=PROBLEMS)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--only", choices=["dask", "ray"], default=None)
    args = ap.parse_args()
    options = BatchOptions(jobs=1, timeout=300)
    t = time.perf_counter()
    local = Batch(ROOT, BatchOptions(jobs=args.workers, timeout=300)).run(args.problems)
    rows = [{"scheduler": "local pool", "check_s": time.perf_counter() - t,
             "check_ok": all(not r.error for r in local)}]
    for name, fn in (("dask", bench_dask), ("ray", bench_ray)):
        if args.only and args.only != name:
            continue
        try:
            rows.append(fn(args.workers, args.problems, options))
        except ImportError as exc:
            rows.append({"scheduler": name, "limit": f"not installed ({exc.name})"})
    cols = ["scheduler", "start_s", "rss_mb", "rss_busy_mb", "task_ms", "check_s", "check_ok",
            "limit_s", "ray_cancel_s", "after_limit_ms", "limit"]
    print(f"{len(args.problems)} problems, {args.workers} workers: " + " ".join(args.problems))
    print(" | ".join(cols))
    for r in rows:
        print(" | ".join(f"{r[c]:.3g}" if isinstance(r.get(c), float) else str(r.get(c, "-"))
                         for c in cols))


if __name__ == "__main__":
    main()
