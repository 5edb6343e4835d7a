"""Finds the keyanim Python module (`import keyanim`) from inside Blender.

Debian's Blender runs the system Python 3.11, so it loads the module built for /usr/bin/python3.
It looks where that module is installed for a user, as Python itself would look outside Blender:
- an override first, so that a build tree wins over an installed module: the directories in
  the KEYANIM_PYTHONPATH environment variable (os.pathsep-separated, e.g. build/python), then
  the add-on preference "keyanim module directory";
- the user site-packages (~/.local/lib/python3.X/site-packages, where scripts/quickstart.sh puts
  it for a user who is not root), which Blender leaves off sys.path although /usr/bin/python3
  searches it: put back where that Python has it, before the system's directories;
- the interpreter's own path, which holds /usr/local/lib/python3.X/dist-packages (where
  `cmake --install` puts it for root, python/install_module.cmake).
"""
import importlib
import os
import site
import sys

ENV = "KEYANIM_PYTHONPATH"


def _override_dirs(preference_dir):
    dirs = [d for d in os.environ.get(ENV, "").split(os.pathsep) if d]
    if preference_dir:
        dirs.append(bpy_abspath(preference_dir))
    return [os.path.abspath(d) for d in dirs]


def bpy_abspath(path):
    """A preference path may be relative to the .blend file ('//'), as Blender writes them."""
    try:
        import bpy
        return bpy.path.abspath(path)
    except ImportError:  # outside Blender (not used there, but keeps the function honest)
        return path


def _add_user_site():
    """Puts the user site-packages where /usr/bin/python3 has it: before the system's
    site-packages directories, so that a user's install wins over /usr/local's, as outside."""
    user_site = site.getusersitepackages()
    if user_site in sys.path:
        return user_site
    system = [i for i, d in enumerate(sys.path) if d in site.getsitepackages()]
    sys.path.insert(system[0] if system else len(sys.path), user_site)
    return user_site


def load(preference_dir=""):
    """The keyanim module, or ImportError saying where it was looked for and how to point at it."""
    user_site = _add_user_site()
    for d in reversed(_override_dirs(preference_dir)):
        if d not in sys.path:
            sys.path.insert(0, d)
    try:
        return importlib.import_module("keyanim")
    except ImportError as e:
        raise ImportError(
            "the keyanim Python module was not found (%s) on Blender's Python path nor in %s: "
            "install it (scripts/quickstart.sh), or point %s or the add-on's preference at the "
            "directory holding keyanim/ (a build tree's build/python)" % (e, user_site, ENV)) from e
