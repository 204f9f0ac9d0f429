"""fitting stage."""
