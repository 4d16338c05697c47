"""``python -m lsys_core.cli``: the ``lsys`` command (:func:`lsys_core.cli.run`)."""

from lsys_core.cli import run

if __name__ == "__main__":
    run()
