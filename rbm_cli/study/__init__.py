"""Studies of runs: simulate through the registry, sweep, ensembles, domains, fragility,
the benchmark. No physics and no plotting. Imports models, structures, inputs, config and
base."""
