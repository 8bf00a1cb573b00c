"""ROS 2 adapters over the core: the ``viscoadh`` node, its parameters, conversions and
diagnostics. The only package of viscoadh_ros that imports rclpy."""
