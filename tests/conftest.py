import jax

# Tests run in float64 (EHL needs it); the library never flips this itself.
jax.config.update("jax_enable_x64", True)
