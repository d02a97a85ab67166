"""`python -m rbm_cli` runs the rbm command line."""

from rbm_cli.cli.main import main

if __name__ == "__main__":  # not when a spawned worker re-imports the main module
    main()
