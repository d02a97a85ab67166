"""Models behind one contract (rbm_cli.models.contract): a registry name -> Runner.

Each runner takes a validated config once (prepare) and then one ground motion per run,
and returns the one result type, rbm_cli.models.result.RunResult. Imports physics,
config and base.
"""
