# Eigen 3 (header-only) -> Eigen3::Eigen
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
