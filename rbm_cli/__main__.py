"""`python -m rbm_cli` runs the rbm command line."""

from rbm_cli.cli.main import main

main()
