# assimp -> assimp::assimp.  Authoring only.
find_package(assimp 5.2 REQUIRED)
