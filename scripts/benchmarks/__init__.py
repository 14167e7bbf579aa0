"""The benchmark cases of scripts/bench.py: one module per case, each with ``main()`` reading its arguments."""
