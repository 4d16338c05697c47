"""Frozen entry point of ``lsys`` (see lsys-editor.spec)."""

if __name__ == "__main__":
    from lsys_core.cli import run

    run()
