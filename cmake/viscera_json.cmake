# nlohmann/json (header-only) -> nlohmann_json::nlohmann_json
find_package(nlohmann_json 3.10 REQUIRED)
