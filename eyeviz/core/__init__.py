"""The geometry core: Propositions 1-5, the exact fallback, the ambiguity polyhedron.

Pure functions on arrays; imports nothing but numpy, mpmath and the standard library."""
