"""Reliability: noisy open-loop rollouts of a plan, record files, a Wilson interval."""
