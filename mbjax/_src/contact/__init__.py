"""Contacts with the ground: holding feet as closures, their wrenches, impulses."""
