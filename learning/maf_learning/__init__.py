"""map_aided_fusion learning: generated drives with a held-out split, and the optuna tuner (learning/tune)."""
