"""Models behind one contract (rbm_cli.models.contract): a registry name -> Runner.

Each runner takes a validated config once (prepare) and then one ground motion per run,
and returns the one result type, rbm_cli.models.outcome.Outcome (with its sampled
History when recording; rbm_cli.study turns it into a domain's row). Imports structures,
numerics, inputs, config and base.
"""
