"""`bullet`: stacked rigid drums in Bullet's contact dynamics (PyBullet)."""
