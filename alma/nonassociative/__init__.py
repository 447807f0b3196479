"""nonassociative."""
