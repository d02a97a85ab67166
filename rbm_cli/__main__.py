"""`python -m rbm_cli` runs the rbm command line."""

from .cli import main

main()
