# CGAL (header-only; pulls GMP/MPFR) -> CGAL::CGAL.  Authoring only: never linked by core or player.
find_package(CGAL 5.5 REQUIRED)
