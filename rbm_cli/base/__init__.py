"""Below everything: errors, deterministic arithmetic, atomic files. Imports nothing of rbm."""
