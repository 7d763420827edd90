"""The process's plumbing, beside the science and its files: what a running command needs from its process.

- :mod:`.signals`: SIGINT and SIGTERM held while files are moved into place, Ctrl-C as a flag
  checked between steps, the one line an interrupted command prints and its exit status;
- :mod:`.joblog`: a pipeline job's log file and its one-line failure on the terminal;
- :mod:`.locks`: Snakemake's lock of a working directory, removed only when no Snakemake runs there;
- :mod:`.progress`: progress bars on stderr;
- :mod:`.budget` and :mod:`.timeout`: wall-clock budgets of a computation (checked by the work) and
  of a block of code (SIGALRM);
- :mod:`.usage`: the exit status of argparse's usage errors.

Private: the names a user meets (``TimeBudgetExceeded``, ``Deadline``) are re-exported by
:mod:`microimpact.solvers`. Nothing here imports the rest of the package, so every room may use it.
"""
