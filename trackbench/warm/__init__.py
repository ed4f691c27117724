"""Start-up machinery, reached from the command line only: the study workers' fork server
(forkserver.py, its preload in preload.py) and what a process does to start sooner
(startup.py). Nothing below cli/ imports this package; the package works without it."""
