"""ament_python package viscoadh_ros: pip (scripts/setup.sh) and colcon build it alike."""

from glob import glob

from setuptools import find_packages, setup

PACKAGE = "viscoadh_ros"

setup(
    name=PACKAGE,
    version="0.12.0",
    packages=find_packages(include=[PACKAGE, f"{PACKAGE}.*"]),
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/config", sorted(glob("config/*.yaml"))),
        (f"share/{PACKAGE}/config/examples", sorted(glob("config/examples/*.yaml"))),
    ],
    package_data={PACKAGE: ["py.typed"]},
    install_requires=["setuptools"],
    # Optional: `batch` (viscoadh fit/replay over many bags on Dask), `gripper` (MuJoCo scene).
    extras_require={
        "batch": ["dask>=2024.1", "distributed>=2024.1"],
        "gripper": ["mujoco>=3.1"],
    },
    zip_safe=True,
    maintainer="viscoadh_ros maintainers",
    maintainer_email="viscoadh-maintainers@contact-mechanics.org",
    description=(
        "Adhesive contact with viscoelastic materials (MDR + energy criterion) "
        "as a ROS 2 node, a CLI and a library"
    ),
    license="Apache-2.0",
    python_requires=">=3.10",
    entry_points={
        "console_scripts": [
            "viscoadh = viscoadh_ros.cli.main:main",
            "viscoadh_node = viscoadh_ros.ros.node:main",
        ],
    },
)
