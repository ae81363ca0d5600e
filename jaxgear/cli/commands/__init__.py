"""Subcommands of the ``jaxgear`` command line (one module each, see ``jaxgear.cli.main``)."""
