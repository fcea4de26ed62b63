"""Numerical integration of the full nonlinear equations of motion.

    model        the equations compiled once per problem (the compile layer's scalar entry)
    methods      the integration methods' names and the options each kind takes
    integrators  SciPy's solve_ivp methods, fixed-step RK4 / symplectic methods and the
                 Taylor method, one interface
    native       loops.c built once per machine, called through ctypes (Model.rhs too)
    compiled     the compiled loops run once per integration (fixed steps, DOP853, RK45)
    events       DOP853 with solve_ivp's events in the compiled loop (event steps in SciPy)
    taylor       heyoka's Taylor method: integration, events, batch mode, float128
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
