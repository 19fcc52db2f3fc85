# Qt6: studio uses Widgets; the player may use Gui only.
find_package(Qt6 REQUIRED COMPONENTS Core Gui)
if(VISCERA_BUILD_STUDIO)
  find_package(Qt6 REQUIRED COMPONENTS Widgets OpenGLWidgets)
endif()
