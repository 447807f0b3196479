"""associative."""
