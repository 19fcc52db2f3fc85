# EGL + desktop GL through libglvnd (Mesa provides llvmpipe) -> OpenGL::EGL, OpenGL::OpenGL
set(OpenGL_GL_PREFERENCE GLVND)
find_package(OpenGL REQUIRED COMPONENTS OpenGL EGL)
