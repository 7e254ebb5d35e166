"""Synthetic frames made from closed forms: the bundled example curves, the lung-like surface pair
and segmented masks and stacks made from them (deterministic; used by the demo, tests and bench)."""
