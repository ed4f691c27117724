"""The ground beside the vehicle: rigid terrain, soft soil (plain and compiled), the
bristle friction's grip, and the ground's memories."""
