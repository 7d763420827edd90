"""Start-up cost of the command line, side by side with ``python -c "import numpy"`` (issue 13).

Each command runs REPEATS times, interleaved with the numpy baseline, and the medians are compared
as ratios (a loaded machine slows both alike). The numba cache is warmed first, so that
``simulate`` is measured warm. Exit status 1 if ``microimpact --help`` costs more than 3 times the
baseline (the issue's target); the other ratios are reported.

    python .ci/startup.py [REPEATS]
"""

import statistics
import subprocess
import sys
import time

REPEATS = int(sys.argv[1]) if len(sys.argv) > 1 else 7
PY = sys.executable
COMMANDS = {
    "python -c 'import numpy'": [PY, "-c", "import numpy"],
    "import microimpact": [PY, "-c", "import microimpact"],
    "microimpact --help": [PY, "-m", "microimpact._entry", "--help"],
    "microimpact simulate --speed 2 (warm)": [PY, "-m", "microimpact._entry", "simulate", "--speed", "2"],
}
HELP_TARGET = 3.0


def seconds(cmd) -> float:
    start = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


seconds(COMMANDS["microimpact simulate --speed 2 (warm)"])  # fills numba's cache if it is cold
times = {name: [] for name in COMMANDS}
for _ in range(REPEATS):
    for name, cmd in COMMANDS.items():
        times[name].append(seconds(cmd))
base = statistics.median(times["python -c 'import numpy'"])
print(f"{'command':40s} {'median [s]':>10s} {'/ numpy':>8s}")
for name, t in times.items():
    print(f"{name:40s} {statistics.median(t):10.3f} {statistics.median(t) / base:8.2f}")
ratio = statistics.median(times["microimpact --help"]) / base
if ratio > HELP_TARGET:
    sys.exit(f"microimpact --help costs {ratio:.2f} times 'import numpy' (target: at most {HELP_TARGET})")
