"""Readers for real sensor logs (CARMEN laser logs; 004's rangefinder chapters)."""

from .carmen import CarmenLog, flaser_angles, read_carmen

__all__ = ["CarmenLog", "flaser_angles", "read_carmen"]
