"""A case run through the stages: compile (case -> scene), the renderer benchmark, an illusion's lane band."""
