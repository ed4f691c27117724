"""The vehicle: the paper's parameters, kinematics, the track's paths, the closed track's
geometry, the sprocket's teeth (plain and compiled) and the drive."""
