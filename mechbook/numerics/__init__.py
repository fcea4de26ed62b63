"""Numerical integration of the full nonlinear equations of motion.

    model        the equations compiled once per problem (the compile layer's scalar entry)
    methods      the integration methods' table: name -> the options it takes and its class
    integrators  `integrate` and `make_integrator`: any method by name, one interface
    integrator_base  that interface (Integrator), the Trajectory it returns, IntegratorError
    scipy_methods    SciPy's solve_ivp methods (RK45, DOP853, Radau, LSODA)
    fixed_step   fixed-step RK4 and the symplectic methods (leapfrog, yoshida4, midpoint)
    native       loops.c built once per machine, called through ctypes (Model.rhs too)
    compiled     the compiled loops run once per integration (fixed steps, DOP853, RK45)
    events       DOP853 with solve_ivp's events in the compiled loop (event steps in SciPy)
    taylor       heyoka's Taylor method: integration (TaylorMethod), events, batch mode, float128
    hyexpr       SymPy -> heyoka expressions by walking the tree; LDLᵀ solve
    monitors     drift of the conserved quantities the engine found
    measure      turning points, periods, mean rates and event times measured along a run
    friction     integrating through stick and slip (phases ended by stop and release events)
    stiffness    time scales from the linearized equations; is a run stiff?
    accuracy     method and tolerance for a requested accuracy (a rule measured by
                 bench/work_precision.py)
    simulate     initial conditions and `simulate`, the entry point of `mechbook simulate`
    plot         coordinates against time and the phase portrait (matplotlib, Agg)

May import: mechbook.engine, mechbook.model, mechbook.core, mechbook.errors,
mechbook.records.
"""
