"""`housner`: Housner's rigid block with its large-rotation equation, integrated by scipy's
Runge-Kutta pairs with exact events (runner.py: the runner and the run; steps.py: the
block's constants, the equation and the event distances on one side; state.py: the moving
state of a run and its recorder). An independent reference for the Rigid Beam Model's rigid
monolith: it shares no integrator with it."""
