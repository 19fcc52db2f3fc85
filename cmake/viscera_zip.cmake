# libzip -> libzip::zip
find_package(libzip REQUIRED)
