/*
 * The FMU's internal global names, prefixed like the FMI functions when the FMU is
 * compiled for static linking (FMI2_FUNCTION_PREFIX or FMI3_FUNCTION_PREFIX defined,
 * e.g. to the model identifier): two FMUs made by inflowsim (a main and a tail rotor)
 * can then be linked into one program.  Without a prefix the names stay as they are
 * (a shared library hides them: -fvisibility=hidden).  Every other function is
 * static; tests/test_fmu.py checks that a prefixed build defines no other global name.
 */
#ifndef INFLOW_NAMES_H
#define INFLOW_NAMES_H

#if defined(FMI2_FUNCTION_PREFIX) || defined(FMI3_FUNCTION_PREFIX)
#define IFS_PASTE_(a, b) a##b
#define IFS_PASTE(a, b) IFS_PASTE_(a, b)
#if defined(FMI2_FUNCTION_PREFIX)
#define IFS_NAME(n) IFS_PASTE(FMI2_FUNCTION_PREFIX, n)
#else
#define IFS_NAME(n) IFS_PASTE(FMI3_FUNCTION_PREFIX, n)
#endif
#define ifs_absdiffmax IFS_NAME(ifs_absdiffmax)
#define ifs_absmax IFS_NAME(ifs_absmax)
#define ifs_advance IFS_NAME(ifs_advance)
#define ifs_build IFS_NAME(ifs_build)
#define ifs_bias_of IFS_NAME(ifs_bias_of)
#define ifs_cheb_matrices IFS_NAME(ifs_cheb_matrices)
#define ifs_descriptor IFS_NAME(ifs_descriptor)
#define ifs_descriptor_of IFS_NAME(ifs_descriptor_of)
#define ifs_flap_delays_of IFS_NAME(ifs_flap_delays_of)
#define ifs_discretize IFS_NAME(ifs_discretize)
#define ifs_do_step IFS_NAME(ifs_do_step)
#define ifs_do_step_choose IFS_NAME(ifs_do_step_choose)
#define ifs_expm IFS_NAME(ifs_expm)
#define ifs_flow_speed IFS_NAME(ifs_flow_speed)
#define ifs_instance_alloc IFS_NAME(ifs_instance_alloc)
#define ifs_instance_calloc IFS_NAME(ifs_instance_calloc)
#define ifs_instance_free IFS_NAME(ifs_instance_free)
#define ifs_instance_start IFS_NAME(ifs_instance_start)
#define ifs_integer_vars IFS_NAME(ifs_integer_vars)
#define ifs_loads_of IFS_NAME(ifs_loads_of)
#define ifs_log IFS_NAME(ifs_log)
#define ifs_lu_solve IFS_NAME(ifs_lu_solve)
#define ifs_mu_check IFS_NAME(ifs_mu_check)
#define ifs_mu_edges IFS_NAME(ifs_mu_edges)
#define ifs_mu_eval IFS_NAME(ifs_mu_eval)
#define ifs_mu_eval_coarse IFS_NAME(ifs_mu_eval_coarse)
#define ifs_mu_eval_fma IFS_NAME(ifs_mu_eval_fma)
#define ifs_mu_fit IFS_NAME(ifs_mu_fit)
#define ifs_mu_part IFS_NAME(ifs_mu_part)
#define ifs_mu_parts IFS_NAME(ifs_mu_parts)
#define ifs_mu_table_apply_ab IFS_NAME(ifs_mu_table_apply_ab)
#define ifs_mu_table_build IFS_NAME(ifs_mu_table_build)
#define ifs_mu_table_eval IFS_NAME(ifs_mu_table_eval)
#define ifs_mu_table_fit IFS_NAME(ifs_mu_table_fit)
#define ifs_norm1 IFS_NAME(ifs_norm1)
#define ifs_power_fit IFS_NAME(ifs_power_fit)
#define ifs_real_vars IFS_NAME(ifs_real_vars)
#define ifs_schedule_apply IFS_NAME(ifs_schedule_apply)
#define ifs_slave_delayed_state IFS_NAME(ifs_slave_delayed_state)
#define ifs_slave_directional IFS_NAME(ifs_slave_directional)
#define ifs_slave_enter_init IFS_NAME(ifs_slave_enter_init)
#define ifs_slave_exit_init IFS_NAME(ifs_slave_exit_init)
#define ifs_slave_get_ints IFS_NAME(ifs_slave_get_ints)
#define ifs_slave_get_reals IFS_NAME(ifs_slave_get_reals)
#define ifs_slave_init IFS_NAME(ifs_slave_init)
#define ifs_slave_set_ints IFS_NAME(ifs_slave_set_ints)
#define ifs_slave_set_reals IFS_NAME(ifs_slave_set_reals)
#define ifs_slave_set_start_time IFS_NAME(ifs_slave_set_start_time)
#define ifs_slave_step IFS_NAME(ifs_slave_step)
#define ifs_slave_refresh IFS_NAME(ifs_slave_refresh)
#define ifs_slave_update_outputs IFS_NAME(ifs_slave_update_outputs)
#define ifs_state_deserialize IFS_NAME(ifs_state_deserialize)
#define ifs_state_get IFS_NAME(ifs_state_get)
#define ifs_state_serialize IFS_NAME(ifs_state_serialize)
#define ifs_state_set IFS_NAME(ifs_state_set)
#define ifs_taylor_count IFS_NAME(ifs_taylor_count)
#define ifs_taylor_prepare IFS_NAME(ifs_taylor_prepare)
#define ifs_taylor_step IFS_NAME(ifs_taylor_step)
#endif

#endif
