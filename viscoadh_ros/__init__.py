"""viscoadh_ros: adhesive contact with viscoelastic materials (MDR + energy criterion) for ROS 2."""

__version__ = "0.12.0"
