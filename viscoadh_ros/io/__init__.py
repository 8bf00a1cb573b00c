"""File adapters: CSV histories, MCAP recording and reading of ROS 2 bags."""
