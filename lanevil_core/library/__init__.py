"""The stock case library and the published dataset's folder names."""
