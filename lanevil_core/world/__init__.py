"""The world a case compiles into: road geometry and layout, the road mesh and paint, roadside props, vegetation
and structures, the environment, and the compiled scene's types."""
