"""Runnable examples: ``python -m morphomap.examples.NAME``."""
