"""The world a case compiles into: road geometry and layout, the road mesh and paint, roadside props (street
furniture, vehicles, people, buildings), vegetation and structures, the environment, and the compiled scene's types."""
