"""How long a task-mode environment takes to build and reset, and the memory it holds, at the
largest solution depths (issue 47 item 4: 94-151 s and 515 MB at depth 10, 681 s at 15, when every
board up to the depth was mapped first). Each depth in a fresh process, so that the maximum
resident memory is its own. Prints JSON:
    python scripts/bench/task_mode.py > docs/results/python-speed/task-mode.json
"""

import json
import platform
import subprocess
import sys

CHILD = """
import json, resource, sys, time
import seads
depth = int(sys.argv[1])
start = time.perf_counter()
env = seads.SeadsEnv("lightsout-cursor", task=True, max_solution_depth=depth)
env.reset(seed=0)
print(json.dumps({"max_solution_depth": depth, "build_and_reset_s": time.perf_counter() - start,
                  "max_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def main() -> None:
    rows = [
        json.loads(subprocess.run([sys.executable, "-c", CHILD, str(d)], check=True,
                                  capture_output=True, text=True).stdout)
        for d in (5, 10, 15)
    ]
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "")
    print(json.dumps({"env": "lightsout-cursor", "processor": cpu, "python": platform.python_version(),
                      "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
