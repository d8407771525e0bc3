# cmake/pkgconfig.cmake: writes rbcontact.pc (RBC_PC_OUT) from share/rbcontact.pc.in (RBC_PC_IN) for the install layout
# CMAKE_INSTALL_PREFIX, CMAKE_INSTALL_LIBDIR, _INCLUDEDIR, _DATADIR (GNUInstallDirs) and PROJECT_VERSION. Included by
# CMakeLists.txt at configure time, or run as a script (tests/install_check.sh, for a layout the build does not use):
#   cmake -DRBC_PC_IN=share/rbcontact.pc.in -DRBC_PC_OUT=x.pc -DCMAKE_INSTALL_PREFIX=P -DCMAKE_INSTALL_LIBDIR=L -P cmake/pkgconfig.cmake
# With a relative libdir (the default) the prefix is found from the file's own location (${pcfiledir}, whose spaces
# pkg-config escapes itself), so `cmake --install --prefix P` and a moved installation work. An absolute directory is
# written as it is, with pkg-config's quoting: a space as `\ `, a `#` as `\#` (pkg-config --cflags then prints
# `-I/opt/my\ dir/include`, one word for make or a shell's eval). Quotes, backslashes, `$` and control characters
# cannot be quoted there: refused, naming the directory.
function(rbc_pc_path out var path)
  if(path MATCHES "[\"'$\\\\\t\r\n]")
    message(FATAL_ERROR "${var} '${path}': the pkg-config file cannot hold a quote, a backslash, a '$' or a control character in a path: give another directory (with the default relative directories of GNUInstallDirs it holds none)")
  endif()
  string(REPLACE " " "\\ " p "${path}")
  string(REPLACE "#" "\\#" p "${p}")
  set(${out} "${p}" PARENT_SCOPE)
endfunction()

function(rbc_write_pkgconfig in out)
  if(NOT DEFINED CMAKE_INSTALL_INCLUDEDIR)
    set(CMAKE_INSTALL_INCLUDEDIR include)
  endif()
  if(NOT DEFINED CMAKE_INSTALL_DATADIR)
    set(CMAKE_INSTALL_DATADIR share)
  endif()
  if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
    rbc_pc_path(RBC_PC_PREFIX CMAKE_INSTALL_PREFIX "${CMAKE_INSTALL_PREFIX}")
  else()
    file(RELATIVE_PATH rel "/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/")
    string(REGEX REPLACE "/$" "" rel "${rel}")
    set(RBC_PC_PREFIX "\${pcfiledir}/${rel}")
  endif()
  foreach(d LIBDIR INCLUDEDIR DATADIR)
    if(IS_ABSOLUTE "${CMAKE_INSTALL_${d}}")
      rbc_pc_path(RBC_PC_${d} CMAKE_INSTALL_${d} "${CMAKE_INSTALL_${d}}")
    else()
      rbc_pc_path(p CMAKE_INSTALL_${d} "${CMAKE_INSTALL_${d}}")
      set(RBC_PC_${d} "\${prefix}/${p}")
    endif()
  endforeach()
  configure_file("${in}" "${out}" @ONLY)
endfunction()

if(CMAKE_SCRIPT_MODE_FILE)
  rbc_write_pkgconfig("${RBC_PC_IN}" "${RBC_PC_OUT}")
endif()
