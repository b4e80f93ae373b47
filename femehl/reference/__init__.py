"""Reference solutions femehl is validated against, computed by other methods than its time stepping."""
