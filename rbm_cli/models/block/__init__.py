"""The rigid block's closed form, shared by the RBM's rigid monolith (`solver.method:
closed-form`) and `housner-linear`: one piece of motion between two events (piece), the
run loop (run), the entry points (closed_form) and the `housner-linear` runner (runner)."""
