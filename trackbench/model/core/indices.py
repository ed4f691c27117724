"""Index tables: the one place that says where each quantity lives in the arrays
the compiled kernels share.

Reduced-coordinate state ``y`` (length ``n_state(nq, n_bristles)``)::

    q   = y[0:nq]          generalised coordinates
    qd  = y[nq:2*nq]       their rates
    W   = y[2*nq]          work done by all contact forces and dampers since t = 0 (J)
    D   = y[2*nq + 1]      energy dissipated by all dampers (contact damping included) (J)
    ...                    the drive's work and its controller's integral (Y_*)
    z_b = y[bristle_state(nq, b)]   the bristle law only (contact/laws.bristle_active): the
                           deflection of free pin b's bristle along the ground (m), b = 1..last
                           free pin; every other model's y ends with the extras

    q[Q_X], q[Q_Y]         chassis mass-centre position (m)
    q[Q_PITCH]             chassis pitch, counter-clockwise (rad)
    q[Q_ARM + i]           arm angle phi_i of road wheel i relative to the chassis (rad)
    q[pin_offset(nw) + 2*(b-1) + k]   coordinate k (0 = x, 1 = y) of free pin b = 1..n_links-1

Pins are numbered 0..n_links from the front track end to the rear one; pins 0 and
n_links are fixed to the chassis. Link b joins pins b and b+1.

The closed layout (track.layout = "closed") has n_links pins, all free, clockwise around
the loop: rows 1..n_links of the pin arrays hold them (q_pin as above), and row 0 is a
copy of row n_links, so that link b still joins rows b and b+1 (link 0 closes the loop).
After the pin coordinates come the sprocket's angle relative to the chassis
(q_sprocket) and the idler carrier's slide along its guide (q_idler).

Absolute state ``z`` of the "lee" solver (model/dynamics/absolute.py)::

    z[Z_X], z[Z_Y], z[Z_PITCH]              chassis mass centre and pitch
    z[z_arm(i) + ZA_X / ZA_Y / ZA_BETA]     arm i: road-wheel centre and absolute arm angle
    z[z_pin(nw) + 2*(b-1) + k]              free pin b, coordinate k

Everything here is a plain constant or a one-line function (model/core/indices_jit.py compiles the
functions for the kernels; this module stays free of numba, so that validating a
scenario or a study file does not load the compiler), and no kernel writes a bare index
into a shared array.
"""

# --- generalised coordinates of the reduced solver --------------------------------
Q_X = 0
Q_Y = 1
Q_PITCH = 2
Q_ARM = 3


def pin_offset(n_wheels):
    """Index in q of the x coordinate of free pin 1."""
    return Q_ARM + n_wheels


def q_pin(n_wheels, b):
    """Index in q of the x coordinate of free pin b (y is the next one)."""
    return Q_ARM + n_wheels + 2 * (b - 1)


Y_WORK = 0               # y[2 nq + Y_WORK]: W
Y_DISSIPATED = 1         # y[2 nq + Y_DISSIPATED]: D
Y_DRIVE_WORK = 2         # work done by the drive on the sprocket (J; closed layout)
Y_DRIVE_INTEGRAL = 3     # integral of the speed error of the speed drive's PI controller (m)
N_Y_EXTRA = 4            # first-order components after (q, qd); the error test leaves them out


def n_state(nq, n_bristles=0):
    """Length of y: (q, qd), the extras, one bristle deflection per free pin with the bristle law."""
    return 2 * nq + N_Y_EXTRA + n_bristles


def nq_of(ny):
    """Number of generalised coordinates of a state of length ny without bristle states (the
    lee solver's; the reduced solver's kernels read nq from the model: pins[PN_NQ])."""
    return (ny - N_Y_EXTRA) // 2


def bristle_state(nq, b):
    """Index in y of the bristle deflection of free pin b (rows 1..pins[PN_LAST]); the bristle
    law only (its y is longer, pins[PN_NY])."""
    return 2 * nq + N_Y_EXTRA + b - 1


def n_coordinates(n_wheels, n_links, closed=False):
    if closed:
        return Q_ARM + n_wheels + 2 * n_links + 2   # pins, sprocket, idler
    return Q_ARM + n_wheels + 2 * (n_links - 1)


def q_sprocket(n_wheels, n_links):
    """Index in q of the sprocket angle relative to the chassis (closed layout; rad, CCW)."""
    return Q_ARM + n_wheels + 2 * n_links


def q_idler(n_wheels, n_links):
    """Index in q of the idler carrier's slide along its guide (closed layout; m, outward)."""
    return Q_ARM + n_wheels + 2 * n_links + 1


# --- absolute coordinates of the lee solver ------------------------------------------
Z_X = 0
Z_Y = 1
Z_PITCH = 2
Z_ARM = 3                # arm i occupies z[Z_ARM + Z_PER_ARM * i : ... + Z_PER_ARM]
Z_PER_ARM = 3
ZA_X = 0                 # road-wheel centre x, relative to z_arm(i)
ZA_Y = 1
ZA_BETA = 2              # absolute arm angle beta_i = pitch + phi_i


def z_arm(i):
    """Index in z of arm i's first coordinate (its wheel centre x)."""
    return Z_ARM + Z_PER_ARM * i


def z_pin(n_wheels):
    """Index in z of the x coordinate of free pin 1 (the end of the rigid bodies)."""
    return Z_ARM + Z_PER_ARM * n_wheels


def n_absolute(n_wheels, n_links):
    return z_pin(n_wheels) + 2 * (n_links - 1)


# --- ground segments, ``seg`` (one row per segment of the terrain polyline) --------
SEG_X0 = 0               # start point
SEG_Y0 = 1
SEG_TX = 2               # unit direction (x increasing along the polyline)
SEG_TY = 3
SEG_LENGTH = 4
SEG_NX = 5               # outward unit normal (out of the ground)
SEG_NY = 6
N_SEG_COLS = 7

# --- link frames, ``lk`` (Work; one row per link, from gaps.link_frames) -------------
LK_TX = 0                # unit direction t, pin b -> pin b+1
LK_TY = 1
LK_LENGTH = 2            # current length
N_LK_COLS = 3

# --- joints of the lee solver: constraint rows (Phi, lambda) and their vectors ``geo`` --
J_X = 0                  # row 2 i + J_X: the x component of joint i
J_Y = 1
N_J_ROWS = 2             # constraint rows per joint (arm pivot)
GEO_RX = 0               # r = R(theta) p_i, the pivot's body point turned with the chassis
GEO_RY = 1
GEO_LX = 2               # l (cos beta, sin beta), the arm from pivot to wheel centre
GEO_LY = 3
N_GEO_COLS = 4

# --- contact pair kinds: the candidate lists hold one block of rows per kind --------
K_WHEEL_LINK = 0         # row: wheel i; entries: links b          (Fig. 3, Eq. 4)
K_WHEEL_PIN = 1          # row: wheel i; entries: free pins b      (Fig. 4)
K_CORNER_LINK = 2        # row: corner c; entries: links b         (Fig. 5 right)
K_CORNER_PIN = 3         # row: corner c; entries: free pins b     (Fig. 6)
K_PIN_GROUND = 4         # row: pin b (0..n_links); entries: segments j   (Fig. 5 left, Eq. 6)
K_GUIDE_LINK = 5         # row: idler or roller j; entries: links b (closed layout)
K_GUIDE_PIN = 6          # row: idler or roller j; entries: free pins b
N_KINDS = 7
K_TEETH = N_KINDS        # no candidate list: a pin against the sprocket's teeth, for the event location


def neighbour_rows(n_wheels, n_corners, n_links, n_guides=0):
    """First row of each kind's block in the candidate lists, and the total row count
    at [N_KINDS]; the kernels get this as ``nbr_rows``."""
    counts = [0] * N_KINDS
    counts[K_WHEEL_LINK] = counts[K_WHEEL_PIN] = n_wheels
    counts[K_CORNER_LINK] = counts[K_CORNER_PIN] = n_corners
    counts[K_PIN_GROUND] = n_links + 1
    counts[K_GUIDE_LINK] = counts[K_GUIDE_PIN] = n_guides
    starts = [0]
    for c in counts:
        starts.append(starts[-1] + c)
    return starts


# A rough ground has thousands of segments; a pin has a few near it. On a ground of more
# segments than this the candidate rows hold this many (a pin with more stops the run with
# Result.GROUND_CANDIDATES) and a pin's candidates are sought within GROUND_WINDOW of the track
# in x: the rows' memory grows with the ground's length, not with its square.
SEGMENT_CANDIDATES = 256
GROUND_WINDOW = 1.0      # m


def neighbour_width(n_links, n_segments):
    """Columns of a candidate row: the count in column NB_COUNT, then the entries."""
    return 1 + max(n_links + 1, min(n_segments, SEGMENT_CANDIDATES))


NB_COUNT = 0             # column of the candidate count; entries follow in 1..count

# --- which pin rows are free, and the state's layout, ``pins`` (int) ---------------------
PN_LAST = 0  # last free pin row: n_links - 1 (paper: pin n_links rides on the chassis), n_links (closed)
PN_CLOSED = 1            # 1: closed loop (row 0 copies row n_links), 0: the paper's ends on the chassis
PN_NQ = 2                # the state's layout: nq, the number of generalised coordinates
PN_NY = 3                # the length of y, n_state(nq, bristle states)
N_PN = 4

# --- sprocket, idler, tensioner and drive of the closed layout, ``loop`` (empty: paper) --
LP_SPROCKET_X = 0        # body point of the sprocket axis (m)
LP_SPROCKET_Y = 1
LP_SPROCKET_INERTIA = 2  # about its axis (kg m^2)
LP_TEETH = 3             # tooth count N
LP_PITCH_RADIUS = 4      # r_p: seat centres (m)
LP_SEAT_RADIUS = 5       # radius of the circular seat between two teeth (m)
LP_TIP_RADIUS = 6        # tooth tips (m)
LP_PIN_RADIUS = 7        # radius of a pin where it meets the teeth (m)
LP_TOOTH_STIFFNESS = 8   # pin-tooth penalty stiffness (N/m, or N/m^n for the power law)
LP_TOOTH_DAMPING = 9     # viscous coefficient of pin-tooth contacts (N s/m)
LP_GUIDE_X = 10          # unit direction of the idler's guide, body frame (outward)
LP_GUIDE_Y = 11
LP_IDLER_MASS = 12       # idler wheel + carrier (kg)
LP_PRELOAD = 13          # tensioner force at slide 0 (N)
LP_TENSIONER_STIFFNESS = 14  # (N/m)
LP_TENSIONER_DAMPING = 15    # (N s/m)
LP_DRIVE_KIND = 16       # DRIVE_* code (model/vehicle/drive.py)
LP_DRIVE_TORQUE = 17     # torque of the torque drive (N m, forward positive)
LP_TARGET = 18           # speed of the speed drive (m/s)
LP_GAIN_P = 19           # PI gains of the speed drive (N m per m/s, N m per m)
LP_GAIN_I = 20
LP_TORQUE_LIMIT = 21     # |torque| of the speed drive at most this (N m)
LP_TRAVEL = 22           # the idler's slide stays within +-travel (m)
LP_FLANK_ANGLE = 23      # flare of the teeth's flanks, the pressure angle (rad)
LP_CURVE = 24  # torque-speed curve: LP_CURVE_POINTS pairs (sprocket speed rad/s, torque N m) after it
LP_CURVE_POINTS = 16
# the drawbar on the chassis (model/vehicle/drive.py): a constant load and the towing rig
LP_DRAWBAR_LOAD = LP_CURVE + 1 + 2 * LP_CURVE_POINTS   # rearward horizontal force at the hitch (N)
LP_HITCH_X = LP_DRAWBAR_LOAD + 1   # body point of the hitch (m)
LP_HITCH_Y = LP_DRAWBAR_LOAD + 2
LP_RIG_SLIP = LP_DRAWBAR_LOAD + 3  # slip the towing rig sets (0: no rig)
LP_RIG_DAMPING = LP_DRAWBAR_LOAD + 4   # dashpot of the rig's carriage on the hitch (N s/m)
# the tooth profile's constants (teeth_jit.tooth_shape of the values above), computed once when
# the vector is built rather than in every evaluation of the pin-tooth contacts
LP_SHAPE = LP_RIG_DAMPING + 1
N_SHAPE = 13
N_LOOP = LP_SHAPE + N_SHAPE

# drive.kind codes (model/vehicle/drive.py)
DRIVE_NONE, DRIVE_TORQUE, DRIVE_SPEED = 0, 1, 2
DRIVES = {"none": DRIVE_NONE, "torque": DRIVE_TORQUE, "speed": DRIVE_SPEED}

# --- idler and support rollers, ``guides`` (row 0 the idler, then the rollers) ---------
G_BX = 0                 # body point of the centre (the idler's at slide 0) (m)
G_BY = 1
G_REACH = 2              # wheel radius + pad h_w (m)
N_G_COLS = 3

# --- the sprocket's kinematics and loads, ClosedWork.spr ------------------------------------
SP_X = 0                 # axis position and velocity (world)
SP_Y = 1
SP_VX = 2
SP_VY = 3
SP_ANGLE = 4             # absolute angle and rate (CCW)
SP_RATE = 5
SP_FX = 6                # out: force of the pins on the sprocket
SP_FY = 7
SP_TORQUE = 8            # out: their torque about the axis (CCW)
N_SP = 9

# --- run counters of the model arrays, ``counters`` -----------------------------------
C_REBUILDS = 0           # candidate-list rebuilds
C_EVALUATIONS = 1        # evaluations of the track forces (stamps the pairs seen in contact)
C_CORNER_FIRST = 2       # the ground corners within reach of the track at the last rebuild:
C_CORNER_END = 3         # first, one past the last (a rough ground has thousands; a few matter)
C_OVERFLOW = 4           # 1 once a pin had more candidate segments than its row holds
N_COUNTERS = 5

# --- scalar parameters, ``par`` ---------------------------------------------------
# P_ARM_MASS .. P_WHEEL_RADIUS hold road wheel 1's values; the kernels read each station's own
# from the arm table (ARMS_*), where a vehicle's wheels may differ
P_CHASSIS_MASS = 0
P_CHASSIS_INERTIA = 1
P_ARM_MASS = 2
P_ARM_INERTIA = 3
P_ARM_LENGTH = 4
P_TORSION_STIFFNESS = 5
P_WHEEL_RADIUS = 6
P_PIN_MASS = 7
P_LINK_LENGTH = 8
P_LINK_STIFFNESS = 9
P_PAD_WHEEL = 10         # h_w
P_PAD_GROUND = 11        # h_g
P_K_WHEEL = 12           # k_w
P_K_GROUND = 13          # k_g
P_GRAVITY = 14
P_SKIN = 15              # neighbour-list margin (m); results do not depend on it
# contact laws (model/contact/laws.py) and dampers; the paper: linear, no damping
P_CONTACT_LAW = 16       # LAW_* code
P_CONTACT_EXPONENT = 17  # n of the power law
P_CONTACT_DAMPING = 18   # DAMPING_* code
P_C_WHEEL = 19           # viscous coefficient of wheel-track contacts, 2 zeta sqrt(k_w m_pin) (N s/m)
P_C_GROUND = 20          # viscous coefficient of ground- and corner-track contacts (N s/m)
P_RESTITUTION_FACTOR = 21  # chi of the restitution-based laws
P_DAMPING_RAMP = 22      # d_r (m)
P_MIN_APPROACH = 23      # approach speed below which v0 counts as this (m/s)
P_LINK_DAMPING = 24      # axial dashpot of every link (N s/m)
P_CONTACT_GEOMETRY = 25   # GEOMETRY_* code (contact/laws.py)
P_FRICTION = 26          # Coulomb coefficient mu between ground and track
P_FRICTION_VELOCITY = 27  # regularising speed of the friction law (m/s)
# soft soil (model/ground/soil_jit.py; 0 in P_SOIL: the rigid ground of the paper)
P_SOIL = 28              # 1: pins press on Bekker soil instead of the ground pads
P_SOIL_N = 29            # Bekker exponent n
P_SOIL_K = 30            # k_c / b + k_phi (N/m^(n+2))
P_SOIL_KE = 31           # unloading / reloading stiffness K_e (Pa/m)
P_PIN_AREA = 32          # ground area one pin stands for: track width x link length (m^2)
P_RUT_X0 = 33            # x of the first cell of the soil's memory (m)
P_RUT_DX = 34            # cell width (m)
P_SOIL_COHESION = 35     # cohesion x the pin's area, c A (N)
P_SOIL_TAN_PHI = 36      # tan of the soil's friction angle
P_SOIL_SHEAR_K = 37      # shear deformation modulus K of Janosi-Hanamoto (m)
# the bristle friction law (contact/laws.FRICTION_BRISTLE): spring and dashpot per ground contact
P_FRICTION_LAW = 38      # FRICTION_* code
P_BRISTLE_K = 39         # tangential stiffness k_t (N/m)
P_BRISTLE_C = 40         # its dashpot, 2 zeta sqrt(k_t m_pin) (N s/m)
N_PAR = 41

# --- columns of Work.grip: each free pin's bristle at the last evaluation (model/ground/grip.py) -------
G_DEFLECTION = 0         # in: its deflection z along the ground's tangent, from y (m)
G_FORCE = 1              # out: the friction force along the tangent (N; 0 off the ground)
G_SPEED = 2              # out: the pin's speed along it (m/s; 0 off the ground)
G_RATE = 3               # out: dz/dt (m/s)
N_GRIP = 4

# --- columns of the arm table, ``arms``: one row per road-wheel station, front to rear --
ARMS_PX = 0              # pivot body point
ARMS_PY = 1
ARMS_PHI0 = 2            # torsion-bar free angle
ARMS_DAMPING = 3         # rotary damper of the station (N m s/rad)
ARMS_LENGTH = 4          # arm length, pivot to wheel centre (m)
ARMS_REACH = 5           # wheel radius + pad h_w: where the track's centre line meets the wheel (m)
ARMS_MASS = 6            # arm + road wheel (kg)
ARMS_INERTIA = 7         # about the wheel centre (kg m^2)
ARMS_STIFFNESS = 8       # torsion bar k_t (N m/rad)
ARMS_DIAGONAL = 9        # the arm's diagonal mass about its pivot, m l^2 + I (kg m^2)
ARMS_RADIUS = 10         # wheel radius (m)
# bump stops (vehicle.bump_stop_stiffness; 0: none, the paper): beyond a stop angle the arm
# gets -k_stop (phi - phi_stop); jounce (the wheel up) is phi below ARMS_JOUNCE, rebound above
ARMS_STOP_K = 11         # k_stop (N m/rad)
ARMS_JOUNCE = 12         # phi of the jounce stop (rad; -inf: none)
ARMS_REBOUND = 13        # phi of the rebound stop (rad; +inf: none)
N_ARMS_COLS = 14

# --- per-evaluation diagnostics, ``diag`` -------------------------------------------
D_STATUS = 0             # 0 ok, else a Status code found in this evaluation
D_POWER = 1              # dW/dt: power of all contact forces (W)
D_E_TENSION = 2          # elastic energy of the links, Eq. (8) (J)
D_E_PAD_WHEEL = 3        # energy of the wheel-side pads (J)
D_E_PAD_GROUND = 4       # energy of the ground-side pads (J)
D_E_TORSION = 5          # energy of the torsion bars (J)
D_E_KINETIC = 6
D_E_GRAVITY = 7          # gravity potential, y measured from 0 (J)
D_GROUND_FX = 8          # total ground force on the track (N)
D_GROUND_FY = 9
D_CORNER_FORCE = 10      # sum of corner (obstacle edge) contact forces (N)
D_CHASSIS_AX = 11        # chassis mass-centre acceleration (m/s^2)
D_CHASSIS_AY = 12
D_MIN_TENSION = 13
D_MAX_TENSION = 14
D_OBSTACLE_FORCE = (
    15  # ground force on the track from obstacles: corners and every segment after the first (N)
)
D_DISSIPATION = 16       # dD/dt: power dissipated by all dampers (W)
D_DRIVE_TORQUE = 17      # torque of the drive on the sprocket, forward positive (N m; closed layout)
D_IDLER_FORCE = 18       # tensioner force along the guide, outward positive (N)
D_TEETH_TORQUE = 19      # torque of the pins on the sprocket, forward positive (N m)
D_DRAWBAR = 20           # force of the drawbar on the chassis, rearward positive (N; closed layout)
D_CHASSIS_ALPHA = 21     # chassis pitch acceleration (rad/s^2; the seat's acceleration needs it)
D_WHEEL = 22             # wheel-track contact force on wheel i: diag[D_WHEEL + 2 i + k]


def diag_tension(n_wheels):
    """Offset of the link tensions, one per link, in diag."""
    return D_WHEEL + 2 * n_wheels


def n_diag(n_wheels, n_links):
    return diag_tension(n_wheels) + n_links


# --- peaks over every accepted step, ``peaks`` (columns: value, time, then the last
#     two samples f, t, f, t used to refine a local extremum by a parabola) ----------
PK_GROUND_FY = 0         # max total vertical ground force (N)
PK_TENSION_MAX = 1       # max link tension (N)
PK_TENSION_MIN = 2       # min link tension (N; negative = compression)
PK_AY_MAX = 3            # max chassis vertical acceleration (m/s^2)
PK_AY_MIN = 4
PK_VX_MIN = 5            # min chassis horizontal velocity (m/s)
PK_ENERGY_BALANCE = 6    # max |paper energy balance - initial| (J)
PK_ENERGY_RESIDUAL = 7   # max |work-based residual| (J)
PK_FIRST_CORNER = 8      # value 1 once a ground corner touched the track; time of first touch
PK_FIRST_COMPRESSION = 9  # value 1 once any link went into compression; time of first
PK_SWITCH = 10           # time (column 1) of the last step ended at a located contact switch
PK_FIRST_OBSTACLE = 11   # value 1 once any part of an obstacle (face, corner, top) touched the track; time
PK_DRIVE_TORQUE = 12     # max drive torque on the sprocket (closed layout)
PK_IDLER_FORCE = 13      # max tensioner force
PK_WHEEL_FY = 14         # max vertical contact force on wheel i: row PK_WHEEL_FY + i


def n_peaks(n_wheels):
    return PK_WHEEL_FY + n_wheels


# --- solver statistics, ``stats`` ----------------------------------------------------
S_STATUS = 0
S_T_FINAL = 1
S_STEPS = 2
S_REJECTED = 3
S_RHS = 4
S_N_OUT = 5
S_H_MIN = 6
S_H_MAX = 7
S_E0 = 8                 # initial total energy: kinetic + elastic (J)
N_STATS = 9

# The time loop's state kept between the calls of a run streamed in chunks (Outputs.resume,
# solvers/common/stepping.py): whether it started and is paused, the sample of the chunk's row
# 0, the samples so far, then what the loop carries from step to step.
RS_STARTED = 0
RS_PAUSED = 1
RS_BASE = 2
RS_N_OUT = 3
RS_T = 4
RS_H = 5
RS_STEPS = 6
RS_REJECTED = 7
RS_H_LO = 8
RS_H_HI = 9
RS_FAC_MAX = 10
RS_AT_SWITCH = 11
RS_E_REF = 12
RS_R_REF = 13
RS_N_RHS = 14
RS_AGE = 15       # the IMEX loop's: steps since its Jacobian, rejections in a row
RS_IN_ROW = 16
RS_ERR_OLD = 17   # the explicit pairs' PI controller: the last accepted step's error
N_RUN_STATE = 18
