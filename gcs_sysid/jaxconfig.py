"""The one place where gcs-sysid configures JAX.

The GP (Cholesky factors of kernel matrices with small noise) and the 6-DOF
simulation (RK4 over minutes of flight) need 64-bit floats. JAX defaults to
32-bit, and the switch is process-wide, so it is flipped here, explicitly, by
the entry points that need it (``gp`` and ``sim`` public functions, the CLI and
the test suite) and never as an import-time side effect.
"""

__all__ = ["enable_x64"]


def enable_x64() -> None:
    """Switch JAX to 64-bit floats (idempotent).

    Called by every public GP and simulation function before it creates arrays.
    """
    import jax

    if not jax.config.read("jax_enable_x64"):
        jax.config.update("jax_enable_x64", True)
