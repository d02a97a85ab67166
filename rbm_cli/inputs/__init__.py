"""What shakes a structure: ground motions (harmonic, pulses, records and their pairs,
synthetic suites), SI inside, and the ground acceleration as the compiled engine evaluates
it; the intensity measures of a record. Imports config and base."""
