"""Running ParaView's pvpython under a virtual X server in the tests."""

import subprocess

#: xvfb-run picking a free display number, with a screen deep enough for OpenGL.
XVFB_ARGS = ["-a", "-s", "-screen 0 1280x1024x24"]
#: What a virtual X server that lost the race for its display number (another
#: one starting beside it) leaves in the client's error output.
LOST_RACE = ("bad X server connection", "vtkXOpenGLRenderWindow::CreateAWindow")


def run(argv, attempts=3, **options):
    """``subprocess.run(argv)`` with text output, tried again up to ``attempts``
    times while the X server was not there for it."""
    for _ in range(attempts):
        done = subprocess.run(argv, capture_output=True, text=True, **options)
        if done.returncode == 0 or not any(sign in done.stderr for sign in LOST_RACE):
            return done
    return done
