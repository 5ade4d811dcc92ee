"""The application layer: the ``affordplan`` command line, the demo, the benches, scene files, video and the
viewer. It may import anything; nothing in the library imports it."""
