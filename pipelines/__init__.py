"""End-to-end jobs (render, capture, score, fidelity study) and the ``c2n`` command."""
