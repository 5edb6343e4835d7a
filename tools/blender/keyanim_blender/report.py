"""Errors as the user sees them: an operator's report (Blender's status bar and Info editor)
naming the file, instead of a Python traceback."""
import contextlib


@contextlib.contextmanager
def errors(operator, path):
    """Reports what keyanim and the file system raise; the caller returns CANCELLED after the
    with block, which is reached only when something was reported."""
    try:
        yield
    except (ImportError, ValueError, OSError, KeyError) as e:  # keyanim.Error is a ValueError
        text = str(e)
        operator.report({"ERROR"}, text if path and path in text else "%s: %s" % (path, text))
