"""The paper's Tables 1, 4 and 6 (and its constants of eqs 22-32) in SI units: the one
source of every default taken from them (case file defaults, solver settings, levelling)."""

#: Table 1: the tribometer
PIN_DIAMETER = 8e-3                   # D of the Hersey number, eq 46 [m]
HOLDER_HEIGHT = -1e-3                 # the holder's surface below the pin's face (a 1 mm pin) [m]

#: Table 4: pin levelling and dry contact
E_STEEL = 210e9                       # Young's modulus of pin and disk [Pa]
NU_STEEL = 0.3                        # Poisson ratio [-]
HARDNESS = 6.99e9                     # pressure cap H [Pa]
LEVELLING_LOAD = 50.0                 # load of the torque balance [N]
LEVELLING_GAINS = (3e-6, 6e-6, 3.75e-7)   # PID gains of eqs 5-7

#: Table 6: lubricant and macro solver
DENSITY = 850.0                       # rho_0 [kg/m^3]
ROELANDS_ALPHA = 22e-9                # alpha_R of eq 23 [1/Pa]
ROELANDS_P0 = 1.96e8                  # p_0,R of eq 23 [Pa]
DH_C1 = 5.9e8                         # C_1 of eq 24 [Pa]
DH_C2 = 1.34                          # C_2 of eq 24 [-]
AMBIENT_PRESSURE = 1e5                # p_amb [Pa]
CAVITATION_PRESSURE = 8e4             # p_cav [Pa]
LOAD = 150.0                          # imposed normal load F_N,imp [N]
RELAXATION_PCON = 0.05                # alpha_pcon of eq 26
MACRO_GAINS = (1.2e-2, 2.4e-2, 1.5e-3)    # K_P, K_I, K_D of eq 29
BOUNDARY_FRICTION = 1.0 / (3.0 * 3.0 ** 0.5)  # C_f,b of eq 32
E_REDUCED = 2.0 / ((1 - NU_STEEL ** 2) / E_STEEL + (1 - NU_STEEL ** 2) / E_STEEL)  # eq 22
