"""Writer processes forked from the test's own, for the kill -9 tests: a fork starts writing at once,
where a fresh interpreter first spends about a second starting and importing vibmeasure on a loaded
2-core machine. What the SIGKILL interrupts is the same: a process in the middle of its writes."""

import os
import signal
import sys
import traceback


class Forked:
    """``fn(*args, out=...)`` in a forked child that reports through ``out`` (a line-buffered pipe);
    the child never returns into the test runner (it ends with ``os._exit``)."""

    def __init__(self, fn, *args):
        r, w = os.pipe()
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:
            code = 1
            try:
                os.close(r)
                with os.fdopen(w, "w", buffering=1) as out:
                    fn(*args, out=out)
                code = 0
            except BaseException:
                traceback.print_exc()
            finally:
                os._exit(code)
        os.close(w)
        self.pid = pid
        self.out = os.fdopen(r)

    def readline(self) -> str:
        return self.out.readline()

    def kill(self) -> str:
        """SIGKILL the child, reap it, and return what it wrote that was not read yet."""
        os.kill(self.pid, signal.SIGKILL)
        os.waitpid(self.pid, 0)
        with self.out:
            return self.out.read()
