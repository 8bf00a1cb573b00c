"""Benchmarks behind `viscoadh bench`: kernel cost against a bare-loop floor, accuracy against
closed forms, presets, DDS round-trip latency against an echo node, replay speed and a soak.

Every timing is taken beside its baseline in the same run and reported as a median of repeats,
because the machines this runs on are shared and noisy. Nothing here asserts a timing.
"""
