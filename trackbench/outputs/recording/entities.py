"""What a recording holds: the entity paths of the side view and the plots, the time line,
the playback speed and the colours, shared by the recorder and the viewer's layout."""

TIMELINE = "sim_time"


PLAYBACK_SPEED = 0.05  # the viewer replays at 1/20 of real time: 0.5 s simulated takes 10 s


E_WORLD = "/world"   # the side view's root: moved under the chassis in a long run's recording
E_GROUND = "/world/ground"


E_SOIL = "/world/ground/soil"  # soft soil only: the surface lowered by the rut so far


E_CHASSIS = "/world/chassis"


E_ARMS = "/world/arms"


E_WHEELS = "/world/wheels"


E_LINKS = "/world/track/links"


E_PINS = "/world/track/pins"


E_WHEEL_FORCE = "/world/forces/wheel_track"


E_GROUND_FORCE = "/world/forces/ground_track"


E_SPROCKET = "/world/sprocket"  # closed layout only: the tooth profile


E_IDLER = "/world/idler/wheel"


E_GUIDE = "/world/idler/guide"


E_ROLLERS = "/world/rollers"


E_WHEEL_FY = "/signals/wheel_force_y"  # one scalar per wheel per row (series "wheel 1" ...)


E_AY = "/signals/chassis_ay"


E_VX = "/signals/chassis_vx"


E_SEAT = "/signals/seat_acceleration_y"  # the driver's seat, the ride metrics' input


E_ENERGY = "/signals/energy"  # kinetic, elastic, gravity, balance per row


E_TENSION = "/signals/link_tension_max"


E_SPROCKET_TORQUE = "/signals/sprocket_torque"  # closed layout only


E_IDLER_FORCE = "/signals/idler_force"


E_PARAMS = "/info/parameters"


E_SOLVER = "/info/solver"


WHEEL_RGB = [
    (230, 25, 75),
    (245, 130, 48),
    (60, 180, 75),
    (0, 130, 200),
    (145, 30, 180),
    (70, 240, 240),
    (240, 50, 230),
    (128, 128, 0),
]


ENERGY_SERIES = (
    ("kinetic", "energy_kinetic", (0, 114, 178)),
    ("elastic", "energy_elastic", (0, 158, 115)),
    ("gravity", "energy_gravity", (213, 94, 0)),
    ("balance", "energy_balance", (0, 0, 0)),
)


CHASSIS_RGB = (60, 60, 60)


ARM_RGB = (110, 110, 110)


GROUND_RGB = (120, 85, 40)


SOIL_RGB = (215, 170, 60)


WHEEL_FORCE_RGB = (200, 0, 0)


GROUND_FORCE_RGB = (150, 60, 200)


SPROCKET_RGB = (40, 60, 110)


IDLER_RGB = (90, 90, 90)


GUIDE_RGB = (180, 120, 60)


ROLLER_RGB = (120, 120, 120)


def wheel_rgb(i):
    return WHEEL_RGB[i % len(WHEEL_RGB)]
