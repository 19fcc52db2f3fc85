# OpenCV core/imgproc/imgcodecs -> opencv_core, opencv_imgproc, opencv_imgcodecs.  Authoring only.
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs)
