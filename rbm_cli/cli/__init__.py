"""The `rbm` command line: thin click commands over the library (see rbm_cli.cli.main)."""
