"""Synthetic labeled data generated with Scenic, for ground truth and benchmarks."""
