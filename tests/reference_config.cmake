# tests/reference_config.cmake -- the reference configuration: affine decomposition = direct assembly,
# reference-configuration FOM = FOM on the moved mesh (geometry, material and load parameters).
rbc_test_exe(test_reference_config)
rbc_add_mpi_test(NAME refconfig_ring RANKS 1 2 COMMAND $<TARGET_FILE:test_reference_config> -options_file runs/ring_on_block.opts -test_mu 0.95,1.05,1.15 LABELS refconfig)
rbc_add_mpi_test(NAME refconfig_half_disks RANKS 1 2 COMMAND $<TARGET_FILE:test_reference_config> -options_file runs/half_disks.opts -test_mu 0.7,0.06,1.3,0.12 LABELS refconfig)
# a stretch (non-conformal: A(mu) has several terms) and a material parameter, elastic and contact
rbc_add_mpi_test(NAME refconfig_punch_stretch RANKS 1 2 COMMAND $<TARGET_FILE:test_reference_config> -options_file runs/flat_punch.opts
  -mu_names height,Ebase -mu_min 0.8,50 -mu_max 1.3,200 -mu_default 1,100 -map_punch stretch -map_punch_stretch_param height -map_punch_stretch_axis 1 -map_punch_stretch_center 0 -param_E_base Ebase
  -test_mu 0.8,50,1.3,200 LABELS refconfig)
