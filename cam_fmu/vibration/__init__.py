"""Vibration of the follower train: a spring-mass between the follower and an end mass, driven by a rise law.

``spectral`` is the residual vibration after a rise from the law's acceleration spectrum (closed forms per
segment), ``train`` integrates the train's equation of motion over the rise and the dwell (scipy, with its
energy balance), ``limit`` finds the smallest ratio r (the top speed) at which a residual tolerance holds,
``optimize`` shapes the harmonic-trapezoid law's split points against the residual over a band of r,
``polydyne`` corrects the cam for the train at one speed (a motion table); the largest fixed step that resolves
the train's ringing is the solvers' (``engine.train_step``).
docs/model.md section 14 has the equations. Imports ``kinematics``, numpy and scipy.
"""
