"""python -m trackbench.daemon SOCKET STAMP: the daemon (started by a command: client.leave_daemon)."""

import sys

from .serving import main

main(sys.argv[1], sys.argv[2])
