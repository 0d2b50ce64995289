!> granbed: Fortran interface to the C ABI of the granbed kernel
!> (kernel/capi/include/granbed.h), by iso_c_binding.
!>
!> The routine FE users call is granbed_vumat_block: a block of nblock
!> material points in the calling convention of explicit user materials
!> (Abaqus/Explicit VUMAT style): arrays dimensioned (nblock, ncomp), the
!> deformation gradient in, the Cauchy stress and the state variables out.
!>
!>   props(8)                   E [Pa], nu, sigma_y [Pa], eta0, c_p, eta_c,
!>                              true density [kg/m^3], friction
!>   defgradNew(nblock, 9)      F11 F22 F33 F12 F23 F31 F21 F32 F13
!>   stateOld/New(nblock, nstatev)  1-6: Cp^-1 (11 22 33 12 23 31; all zero
!>                              = virgin state), 7: eta, 8: plastic flag
!>   stressNew(nblock, 6)       Cauchy stress [Pa], 11 22 33 12 23 31, in the
!>                              global basis (Abaqus expects the co-rotational
!>                              one: rotate by R of F = RU in a VUMAT wrapper)
!>   status(nblock)             GRANBED_OK or the point's error code
!>
!> For a host with its own state layout, granbed_update_points updates n
!> points in the C ABI's layout (arrays stored point by point: F(9, n)
!> row-major per point, cp_inv(6, n) and stress(6, n) in Voigt order xx yy
!> zz yz xz xy, from granbed_state_init), Kirchhoff or Cauchy stress, with
!> each point's record (J, eta, dissipation, plastic flag, iterations).
!>
!> Link with the static library: gfortran ... libgranbed.a -lm
module granbed
  use, intrinsic :: iso_c_binding, only: c_int32_t, c_size_t, c_double, c_char, c_ptr, &
       c_null_char, c_f_pointer
  implicit none
  private
  public :: granbed_vumat_block, granbed_preset_props, granbed_check_props, granbed_derived_props, &
       granbed_message, granbed_state_init, granbed_update_points

  integer(c_int32_t), parameter, public :: GRANBED_OK = 0
  integer(c_int32_t), parameter, public :: GRANBED_ERR_INVALID_PARAMETER = 2
  integer(c_int32_t), parameter, public :: GRANBED_ERR_POINT_FAILED = 9
  integer, parameter, public :: GRANBED_VUMAT_NPROPS = 8, GRANBED_VUMAT_NSTATEV = 8
  integer(c_int32_t), parameter, public :: GRANBED_STRESS_KIRCHHOFF = 0, GRANBED_STRESS_CAUCHY = 1

  !> struct GranbedPointInfo: one point's record of granbed_update_points.
  type, bind(c), public :: granbed_point_info
     real(c_double) :: j, eta, dissipation_density, hourglass_energy
     integer(c_int32_t) :: plastic, iterations
  end type granbed_point_info

  !> struct GranbedMaterialParams (8 doubles) and GranbedParamError.
  type, bind(c), public :: granbed_material_params
     real(c_double) :: youngs_modulus_pa, poisson_ratio, yield_stress_pa, eta0, cp, eta_c, &
          true_density_kg_m3, friction
  end type granbed_material_params

  !> struct GranbedMaterialDerived: lambda, mu, K, lambda + 2 mu [Pa], rho0
  !> [kg/m^3], c_d [m/s].
  type, bind(c), public :: granbed_material_derived
     real(c_double) :: lambda_pa, mu_pa, bulk_pa, p_wave_pa, density0_kg_m3, wave_speed_m_s
  end type granbed_material_derived

  type, bind(c), public :: granbed_param_error
     character(kind=c_char) :: field(40)
     character(kind=c_char) :: allowed(80)
     real(c_double) :: value
  end type granbed_param_error

  interface
     integer(c_int32_t) function c_granbed_vumat(nblock, nstatev, nprops, props, defgrad_new, &
          state_old, state_new, stress_new, point_status) bind(c, name='granbed_vumat')
       import :: c_int32_t, c_size_t, c_double
       integer(c_size_t), value :: nblock, nstatev, nprops
       real(c_double), intent(in) :: props(*), defgrad_new(*), state_old(*)
       real(c_double), intent(out) :: state_new(*), stress_new(*)
       integer(c_int32_t), intent(out) :: point_status(*)
     end function c_granbed_vumat

     integer(c_int32_t) function c_granbed_material_check(params, error) &
          bind(c, name='granbed_material_check')
       import :: c_int32_t, granbed_material_params, granbed_param_error
       type(granbed_material_params), intent(in) :: params
       type(granbed_param_error), intent(out) :: error
     end function c_granbed_material_check

     integer(c_int32_t) function c_granbed_material_preset(name, params) &
          bind(c, name='granbed_material_preset')
       import :: c_int32_t, c_char, granbed_material_params
       character(kind=c_char), intent(in) :: name(*)
       type(granbed_material_params), intent(out) :: params
     end function c_granbed_material_preset

     integer(c_int32_t) function c_granbed_material_derived(params, out, error) &
          bind(c, name='granbed_material_derived')
       import :: c_int32_t, granbed_material_params, granbed_material_derived, granbed_param_error
       type(granbed_material_params), intent(in) :: params
       type(granbed_material_derived), intent(out) :: out
       type(granbed_param_error), intent(out) :: error
     end function c_granbed_material_derived

     integer(c_int32_t) function c_granbed_state_init(n, cp_inv) bind(c, name='granbed_state_init')
       import :: c_int32_t, c_size_t, c_double
       integer(c_size_t), value :: n
       real(c_double), intent(out) :: cp_inv(*)
     end function c_granbed_state_init

     integer(c_int32_t) function c_granbed_update_points(params, volume_fix, n, f, cp_inv, &
          stress_measure, stress, info, point_status) bind(c, name='granbed_update_points')
       import :: c_int32_t, c_size_t, c_double, granbed_material_params, granbed_point_info
       type(granbed_material_params), intent(in) :: params
       integer(c_int32_t), value :: volume_fix, stress_measure
       integer(c_size_t), value :: n
       real(c_double), intent(in) :: f(*)
       real(c_double), intent(inout) :: cp_inv(*)
       real(c_double), intent(out) :: stress(*)
       type(granbed_point_info), intent(out) :: info(*)
       integer(c_int32_t), intent(out) :: point_status(*)
     end function c_granbed_update_points

     type(c_ptr) function c_granbed_status_message(code) bind(c, name='granbed_status_message')
       import :: c_ptr, c_int32_t
       integer(c_int32_t), value :: code
     end function c_granbed_status_message
  end interface

contains

  !> Updates a block of nblock points (layout in the module header). Returns
  !> in ierr GRANBED_OK, GRANBED_ERR_POINT_FAILED (see status) or an
  !> argument error code (see granbed_message).
  subroutine granbed_vumat_block(nblock, nstatev, nprops, props, defgradNew, stateOld, stateNew, &
       stressNew, status, ierr)
    integer, intent(in) :: nblock, nstatev, nprops
    real(c_double), intent(in) :: props(nprops), defgradNew(nblock, 9), stateOld(nblock, nstatev)
    real(c_double), intent(out) :: stateNew(nblock, nstatev), stressNew(nblock, 6)
    integer(c_int32_t), intent(out) :: status(nblock)
    integer(c_int32_t), intent(out) :: ierr
    ierr = c_granbed_vumat(int(nblock, c_size_t), int(nstatev, c_size_t), int(nprops, c_size_t), &
         props, defgradNew, stateOld, stateNew, stressNew, status)
  end subroutine granbed_vumat_block

  !> The initial plastic state C_p^-1 = identity of n points: cp_inv(6, n).
  subroutine granbed_state_init(n, cp_inv, ierr)
    integer, intent(in) :: n
    real(c_double), intent(out) :: cp_inv(6, n)
    integer(c_int32_t), intent(out) :: ierr
    ierr = c_granbed_state_init(int(n, c_size_t), cp_inv)
  end subroutine granbed_state_init

  !> Updates n points to their end-of-step deformation gradients F(9, n)
  !> (F11 F12 F13 F21 ... F33 per point); cp_inv(6, n) in/out (a failed
  !> point keeps its state); stress(6, n) out, Pa, GRANBED_STRESS_KIRCHHOFF
  !> or GRANBED_STRESS_CAUCHY; info(n) and status(n) per point. volume_fix:
  !> .true. as recommended. ierr: GRANBED_OK, GRANBED_ERR_POINT_FAILED (see
  !> status) or an argument error (nothing written).
  subroutine granbed_update_points(props, volume_fix, n, f, cp_inv, stress_measure, stress, info, &
       status, ierr)
    real(c_double), intent(in) :: props(GRANBED_VUMAT_NPROPS)
    logical, intent(in) :: volume_fix
    integer, intent(in) :: n
    real(c_double), intent(in) :: f(9, n)
    real(c_double), intent(inout) :: cp_inv(6, n)
    integer(c_int32_t), intent(in) :: stress_measure
    real(c_double), intent(out) :: stress(6, n)
    type(granbed_point_info), intent(out) :: info(n)
    integer(c_int32_t), intent(out) :: status(n), ierr
    integer(c_int32_t) :: fix
    fix = 0
    if (volume_fix) fix = 1
    ierr = c_granbed_update_points(params_of(props), fix, int(n, c_size_t), f, cp_inv, &
         stress_measure, stress, info, status)
  end subroutine granbed_update_points

  !> props(1:8) of the standard granule type name ('A1' ... 'C3').
  subroutine granbed_preset_props(name, props, ierr)
    character(len=*), intent(in) :: name
    real(c_double), intent(out) :: props(GRANBED_VUMAT_NPROPS)
    integer(c_int32_t), intent(out) :: ierr
    type(granbed_material_params) :: p
    ierr = c_granbed_material_preset(trim(name)//c_null_char, p)
    props = [p%youngs_modulus_pa, p%poisson_ratio, p%yield_stress_pa, p%eta0, p%cp, p%eta_c, &
         p%true_density_kg_m3, p%friction]
  end subroutine granbed_preset_props

  !> Checks props(1:8); on failure message names the field, value and range.
  subroutine granbed_check_props(props, ierr, message)
    real(c_double), intent(in) :: props(GRANBED_VUMAT_NPROPS)
    integer(c_int32_t), intent(out) :: ierr
    character(len=*), intent(out) :: message
    type(granbed_param_error) :: e
    ierr = c_granbed_material_check(params_of(props), e)
    message = ''
    if (ierr == GRANBED_ERR_INVALID_PARAMETER) then
       write (message, '(3a,g0,2a)') 'invalid material parameter ', trim(c_string(e%field)), &
            ' = ', e%value, ': allowed range is ', trim(c_string(e%allowed))
    end if
  end subroutine granbed_check_props

  !> The constants derived from props(1:8), for a host's stable time step
  !> (dt <= h / c_d for an element of size h) and hourglass stiffness:
  !> derived = [lambda, mu, K, lambda + 2 mu (Pa), rho0 (kg/m^3), c_d (m/s)].
  !> ierr is GRANBED_ERR_INVALID_PARAMETER for props that granbed_check_props
  !> rejects (then derived is zero).
  subroutine granbed_derived_props(props, derived, ierr)
    real(c_double), intent(in) :: props(GRANBED_VUMAT_NPROPS)
    real(c_double), intent(out) :: derived(6)
    integer(c_int32_t), intent(out) :: ierr
    type(granbed_material_derived) :: d
    type(granbed_param_error) :: e
    ierr = c_granbed_material_derived(params_of(props), d, e)
    derived = 0
    if (ierr == GRANBED_OK) derived = [d%lambda_pa, d%mu_pa, d%bulk_pa, d%p_wave_pa, &
         d%density0_kg_m3, d%wave_speed_m_s]
  end subroutine granbed_derived_props

  !> props(1:8) as the C struct GranbedMaterialParams.
  pure function params_of(props) result(p)
    real(c_double), intent(in) :: props(GRANBED_VUMAT_NPROPS)
    type(granbed_material_params) :: p
    p = granbed_material_params(props(1), props(2), props(3), props(4), props(5), props(6), &
         props(7), props(8))
  end function params_of

  !> The message of status code code.
  function granbed_message(code) result(message)
    integer(c_int32_t), intent(in) :: code
    character(len=96) :: message
    character(kind=c_char), pointer :: chars(:)
    call c_f_pointer(c_granbed_status_message(code), chars, [96])
    message = c_string(chars)
  end function granbed_message

  function c_string(chars) result(text)
    character(kind=c_char), intent(in) :: chars(:)
    character(len=size(chars)) :: text
    integer :: i
    text = ''
    do i = 1, size(chars)
       if (chars(i) == c_null_char) exit
       text(i:i) = chars(i)
    end do
  end function c_string
end module granbed
