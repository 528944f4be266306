import jax

# Accuracy work is float64 (DESIGN.md); the library itself never flips this flag.
jax.config.update("jax_enable_x64", True)
