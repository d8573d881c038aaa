# Install rules and the Debian package (CPack DEB): `cpack` in a build folder makes
# sunvo_<version>_<arch>.deb from what that folder built (arm64 from the aarch64 preset, amd64 from
# release). Included at the end of the top-level CMakeLists.txt, after every target exists.
#
# Contents: the onboard program sunvo_rover (once firmware_app defines it) and the command-line
# tools below in /usr/bin; the deployment config in /etc/sunvo (conffile) with what it names (the
# Sun-CNN model in /usr/share/sunvo, a calibration placeholder in /etc/sunvo); the systemd unit
# (config/systemd); the udev rules (config/udev, conffile); maintainer scripts (config/debian)
# that create the sunvo user in the video, gpio and dialout groups. scripts/check_deb.sh checks a
# built package; docs/deployment.md describes installing it.

set(_sunvo_programs
    sunvo_rover             # firmware_app/main: the onboard program
    sunvo_replay_cli        # sunvo_replay: a recorded drive through the whole chain
    sunvo_eval              # trajectory metrics (Table 1, APE/RPE)
    sunvo_sun_tool          # sunvo_sun: SPA sun direction for a place and time
    sunvo_geodesy_cli       # sunvo_geodesy: OXTS -> ENU poses
    sunvo_kitti_replay_cli  # sunvo_kitti_replay: paced KITTI raw playback
    sunvo_track_vo          # track-mode VO on recorded feature tracks
    sunvo_pose_reader)      # MAVLink ODOMETRY reader for the serial link
# sunvo_packaged_programs builds just what the package installs (cpack does not build).
add_custom_target(sunvo_packaged_programs)
foreach(_program IN LISTS _sunvo_programs)
  if(TARGET ${_program})
    install(TARGETS ${_program} RUNTIME DESTINATION bin)
    add_dependencies(sunvo_packaged_programs ${_program})
  endif()
endforeach()

# Conffiles: dpkg keeps the administrator's edits of these on upgrade.
set(_sunvo_conffiles /etc/udev/rules.d/60-sunvo.rules)
if(EXISTS "${CMAKE_SOURCE_DIR}/config/rover.yaml")
  install(FILES config/rover.yaml DESTINATION /etc/sunvo)
  list(APPEND _sunvo_conffiles /etc/sunvo/rover.yaml)
  # What rover.yaml names (scripts/check_deb.sh checks every path in it): the Sun-CNN model and
  # its model card (sun.model), and a placeholder for the stereo calibration
  # (source.v4l2.calibration), a conffile that stops the program until the administrator puts
  # the pair's own calibration there; dpkg keeps that file on upgrades.
  install(FILES config/sun_cnn.onnx config/sun_cnn.json config/sun_cnn_gray.onnx config/sun_cnn_gray.json
          DESTINATION share/sunvo)
  install(FILES config/debian/calib_cam_to_cam.txt DESTINATION /etc/sunvo)
  list(APPEND _sunvo_conffiles /etc/sunvo/calib_cam_to_cam.txt)
endif()
if(EXISTS "${CMAKE_SOURCE_DIR}/config/rover_replay.yaml")
  install(FILES config/rover_replay.yaml DESTINATION share/sunvo/examples)
endif()
install(FILES config/systemd/sunvo.service DESTINATION /lib/systemd/system)
install(FILES config/udev/60-sunvo.rules DESTINATION /etc/udev/rules.d)
install(FILES docs/deployment.md DESTINATION share/doc/sunvo)

list(JOIN _sunvo_conffiles "\n" _sunvo_conffiles_text)
file(WRITE "${CMAKE_BINARY_DIR}/debian/conffiles" "${_sunvo_conffiles_text}\n")
foreach(_script postinst prerm postrm)
  file(COPY "${CMAKE_SOURCE_DIR}/config/debian/${_script}" DESTINATION "${CMAKE_BINARY_DIR}/debian"
       FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ
                        WORLD_EXECUTE)
endforeach()

# Debian architecture of the target (not of the host: cpack would ask dpkg, which says amd64
# when cross-compiling).
if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64)$")
  set(_sunvo_deb_arch arm64)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  set(_sunvo_deb_arch amd64)
else()
  set(_sunvo_deb_arch "${CMAKE_SYSTEM_PROCESSOR}")
endif()

# Runtime dependencies: the Debian 12 packages holding the shared libraries the installed
# programs link directly (readelf -d NEEDED), plus adduser for postinst. Not from
# CPACK_DEBIAN_PACKAGE_SHLIBDEPS: dpkg-shlibdeps looks libraries up in the host's dpkg database,
# which knows no arm64 packages when cross-compiling. scripts/check_deb.sh derives the list
# again from the packaged binaries and the arm64 sysroot's packages and fails on any difference.
# Versions: those of Debian 12 (bookworm), which the sysroot and the x86-64 build use.
# BLAS/LAPACK: the programs link ATLAS' libf77blas.so.3 and the liblapack.so.3 alternative,
# which libatlas3-base provides.
set(SUNVO_DEB_DEPENDS
    "adduser"
    "libatlas3-base (>= 3.10.3)"
    "libc6 (>= 2.36)"
    "libcholmod3 (>= 1:5.12.0)"
    "libcxsparse3 (>= 1:5.12.0)"
    "libgcc-s1 (>= 12.2.0)"
    "libgeographiclib23 (>= 2.1.2)"
    "libgoogle-glog0v6 (>= 0.6.0)"
    "libopencv-core406 (>= 4.6.0)"
    "libopencv-imgcodecs406 (>= 4.6.0)"
    "libopencv-imgproc406 (>= 4.6.0)"
    "libstdc++6 (>= 12.2.0)")

# Libraries only some programs link (sunvo_rover: the YAML config; the GPIO driver once it is
# linked; OpenCV's dnn module through the Sun-CNN estimator, calib3d through the rectifier): their package is added when a packaged program links them, found by walking the
# programs' link libraries (static sunvo libraries pass theirs on as $<LINK_ONLY:...>).
function(_sunvo_link_closure target out_var)
  set(seen ${${out_var}})
  set(todo ${target})
  while(todo)
    list(POP_FRONT todo item)
    string(REGEX REPLACE "^\\$<LINK_ONLY:(.*)>$" "\\1" item "${item}")
    if(item IN_LIST seen)
      continue()
    endif()
    list(APPEND seen "${item}")
    if(TARGET "${item}")
      get_target_property(_type "${item}" TYPE)
      get_target_property(_iface "${item}" INTERFACE_LINK_LIBRARIES)
      if(_iface)
        list(APPEND todo ${_iface})
      endif()
      if(NOT _type STREQUAL "INTERFACE_LIBRARY")
        get_target_property(_libs "${item}" LINK_LIBRARIES)
        if(_libs)
          list(APPEND todo ${_libs})
        endif()
      endif()
    endif()
  endwhile()
  set(${out_var} ${seen} PARENT_SCOPE)
endfunction()
set(_sunvo_linked "")
foreach(_program IN LISTS _sunvo_programs)
  if(TARGET ${_program})
    _sunvo_link_closure(${_program} _sunvo_linked)
  endif()
endforeach()
if("yaml-cpp" IN_LIST _sunvo_linked)
  list(APPEND SUNVO_DEB_DEPENDS "libyaml-cpp0.7 (>= 0.7.0)")
endif()
if("opencv_dnn" IN_LIST _sunvo_linked)
  list(APPEND SUNVO_DEB_DEPENDS "libopencv-dnn406 (>= 4.6.0)")
endif()
if("opencv_calib3d" IN_LIST _sunvo_linked)
  list(APPEND SUNVO_DEB_DEPENDS "libopencv-calib3d406 (>= 4.6.0)")
endif()
if(SUNVO_GPIOD_LIBRARY AND "${SUNVO_GPIOD_LIBRARY}" IN_LIST _sunvo_linked)
  list(APPEND SUNVO_DEB_DEPENDS "libgpiod2 (>= 1.6.3)")
endif()
list(SORT SUNVO_DEB_DEPENDS)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME sunvo)
set(CPACK_PACKAGE_VERSION "${PROJECT_VERSION}")
set(CPACK_PACKAGE_CONTACT "sunvo maintainers <sunvo@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "sun-aided stereo visual odometry for rovers")
set(CPACK_PACKAGE_DESCRIPTION
    "sunvo_rover estimates the rover's pose from a stereo camera pair and the sun's direction and streams it to the autopilot as MAVLink ODOMETRY; runs as the systemd service sunvo.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE "${_sunvo_deb_arch}")
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
list(JOIN SUNVO_DEB_DEPENDS ", " CPACK_DEBIAN_PACKAGE_DEPENDS)
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    "${CMAKE_BINARY_DIR}/debian/conffiles;${CMAKE_BINARY_DIR}/debian/postinst;${CMAKE_BINARY_DIR}/debian/prerm;${CMAKE_BINARY_DIR}/debian/postrm")
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
