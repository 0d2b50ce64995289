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
!> The one-point hex of the kernel, for a host's own mesh: granbed_hex_reference
!> once (x_ref(3, 8, n): coordinates of each element's 8 nodes in the
!> trilinear order, m) into reference(GRANBED_HEX_REFERENCE_LEN, n), then
!> granbed_hex_forces every step: x(3, 8, n) in, cp_inv(6, n) in/out,
!> f(3, 8, n) out (internal plus hourglass force, N; m a = f_ext - f), with
!> tau(6, n) and info(n) if asked for.
!>
!> Contact, one node-to-face constraint at a time: granbed_project_node
!> (closest point of a node on a bilinear quad(3, 4)) and granbed_face_force
!> (the force that closes the predicted gap, with Coulomb friction). The
!> derived types mirror the C structs; C's [corner][xyz] arrays are
!> (xyz, corner) here.
!>
!> Link with the static library: gfortran ... libgranbed.a -lm
module granbed
  use, intrinsic :: iso_c_binding, only: c_int32_t, c_size_t, c_double, c_char, c_ptr, &
       c_null_char, c_f_pointer
  implicit none
  private
  public :: granbed_vumat_block, granbed_preset_props, granbed_check_props, granbed_derived_props, &
       granbed_message, granbed_state_init, granbed_update_points, granbed_hex_reference, &
       granbed_hex_forces, granbed_project_node, granbed_face_force

  ! The header's constants (.ci/capi-check compares them with granbed.h).
  integer(c_int32_t), parameter, public :: GRANBED_OK = 0
  integer(c_int32_t), parameter, public :: GRANBED_ERR_NULL_POINTER = 1
  integer(c_int32_t), parameter, public :: GRANBED_ERR_INVALID_PARAMETER = 2
  integer(c_int32_t), parameter, public :: GRANBED_ERR_INVALID_ARGUMENT = 3
  integer(c_int32_t), parameter, public :: GRANBED_ERR_NON_FINITE = 4
  integer(c_int32_t), parameter, public :: GRANBED_ERR_INVERTED = 5
  integer(c_int32_t), parameter, public :: GRANBED_ERR_INVALID_STATE = 6
  integer(c_int32_t), parameter, public :: GRANBED_ERR_NO_CONVERGENCE = 7
  integer(c_int32_t), parameter, public :: GRANBED_ERR_DEGENERATE = 8
  integer(c_int32_t), parameter, public :: GRANBED_ERR_POINT_FAILED = 9
  integer(c_int32_t), parameter, public :: GRANBED_ERR_SIZE = 10
  integer, parameter, public :: GRANBED_VUMAT_NPROPS = 8, GRANBED_VUMAT_NSTATEV = 8
  integer(c_int32_t), parameter, public :: GRANBED_STRESS_KIRCHHOFF = 0, GRANBED_STRESS_CAUCHY = 1
  integer, parameter, public :: GRANBED_HEX_REFERENCE_LEN = 66
  real(c_double), parameter, public :: GRANBED_DEFAULT_HOURGLASS_KAPPA = 0.05_c_double
  real(c_double), parameter, public :: GRANBED_INSIDE_TOLERANCE = 1e-6_c_double
  real(c_double), parameter, public :: GRANBED_UNIT_TOLERANCE = 1e-6_c_double

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

  !> struct GranbedQuadProjection: where a point projects on a bilinear quad:
  !> local coordinates (xi, eta) in [-1, 1]^2, the closest point (m), the
  !> unit outward normal, the signed gap (m, negative behind the face), the
  !> corners' bilinear weights and inside (1 within GRANBED_INSIDE_TOLERANCE).
  type, bind(c), public :: granbed_quad_projection
     real(c_double) :: xi, eta, point(3), normal(3), gap, weights(4)
     integer(c_int32_t) :: inside
  end type granbed_quad_projection

  !> struct GranbedNodeFace: one node-to-face constraint (masses kg,
  !> positions m at the step's start and predicted; master corners as
  !> (xyz, corner)); weights, normal and gap from granbed_project_node of the
  !> predicted node on the predicted face.
  type, bind(c), public :: granbed_node_face
     real(c_double) :: slave_mass, slave_x_n(3), slave_x_pred(3), master_mass(4)
     real(c_double) :: master_x_n(3, 4), master_x_pred(3, 4), weights(4), normal(3), gap
  end type granbed_node_face

  !> struct GranbedNodeFaceForce: the force on the slave node and on each
  !> master corner (xyz, corner), N; its friction part, the normal force
  !> magnitude, and slipping (1 on the Coulomb cap).
  type, bind(c), public :: granbed_node_face_force
     real(c_double) :: slave(3), master(3, 4), friction(3), normal
     integer(c_int32_t) :: slipping
  end type granbed_node_face_force

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

     integer(c_int32_t) function c_granbed_hex_reference(n, x_ref, reference, element_status) &
          bind(c, name='granbed_hex_reference')
       import :: c_int32_t, c_size_t, c_double
       integer(c_size_t), value :: n
       real(c_double), intent(in) :: x_ref(*)
       real(c_double), intent(out) :: reference(*)
       integer(c_int32_t), intent(out) :: element_status(*)
     end function c_granbed_hex_reference

     integer(c_int32_t) function c_granbed_hex_forces(params, volume_fix, kappa, n, reference, x, &
          cp_inv, f, tau, info, element_status) bind(c, name='granbed_hex_forces')
       import :: c_int32_t, c_size_t, c_double, granbed_material_params, granbed_point_info
       type(granbed_material_params), intent(in) :: params
       integer(c_int32_t), value :: volume_fix
       real(c_double), value :: kappa
       integer(c_size_t), value :: n
       real(c_double), intent(in) :: reference(*), x(*)
       real(c_double), intent(inout) :: cp_inv(*)
       real(c_double), intent(out) :: f(*)
       ! Absent optional arguments arrive as NULL (Fortran 2018).
       real(c_double), intent(out), optional :: tau(*)
       type(granbed_point_info), intent(out), optional :: info(*)
       integer(c_int32_t), intent(out) :: element_status(*)
     end function c_granbed_hex_forces

     integer(c_int32_t) function c_granbed_project_node_on_quad(p, quad, out) &
          bind(c, name='granbed_project_node_on_quad')
       import :: c_int32_t, c_double, granbed_quad_projection
       real(c_double), intent(in) :: p(*), quad(*)
       type(granbed_quad_projection), intent(out) :: out
     end function c_granbed_project_node_on_quad

     integer(c_int32_t) function c_granbed_node_face_force(c, weight, friction, dt_squared, out) &
          bind(c, name='granbed_node_face_force')
       import :: c_int32_t, c_double, granbed_node_face, granbed_node_face_force
       type(granbed_node_face), intent(in) :: c
       real(c_double), value :: weight, friction, dt_squared
       ! Not written on an error.
       type(granbed_node_face_force), intent(inout) :: out
     end function c_granbed_node_face_force

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
    ierr = c_granbed_update_points(params_of(props), flag_of(volume_fix), int(n, c_size_t), f, cp_inv, &
         stress_measure, stress, info, status)
  end subroutine granbed_update_points

  !> The reference data of n hexes: x_ref(3, 8, n), the nodes of each in the
  !> trilinear order (1 at (-,-,-), 2 (+,-,-), 3 (+,+,-), 4 (-,+,-), then
  !> 5-8 the same at +zeta), m; reference(GRANBED_HEX_REFERENCE_LEN, n) out
  !> (V0, B0, gamma0, the hourglass geometry factor and the node volumes,
  !> as granbed.h lists them). status(n): GRANBED_ERR_DEGENERATE for a hex
  !> with a non-positive Jacobian. ierr: GRANBED_OK, GRANBED_ERR_POINT_FAILED
  !> (see status) or an argument error.
  subroutine granbed_hex_reference(n, x_ref, reference, status, ierr)
    integer, intent(in) :: n
    real(c_double), intent(in) :: x_ref(3, 8, n)
    real(c_double), intent(out) :: reference(GRANBED_HEX_REFERENCE_LEN, n)
    integer(c_int32_t), intent(out) :: status(n), ierr
    ierr = c_granbed_hex_reference(int(n, c_size_t), x_ref, reference, status)
  end subroutine granbed_hex_reference

  !> Internal plus hourglass nodal forces of n one-point hexes at the current
  !> node coordinates x(3, 8, n), m: f(3, 8, n) out, N (zero for a failed
  !> element; the equation of motion subtracts it: m a = f_ext - f).
  !> cp_inv(6, n) in/out (a failed element keeps its state); kappa the
  !> hourglass coefficient (GRANBED_DEFAULT_HOURGLASS_KAPPA); volume_fix
  !> .true. as recommended. Optional: tau(6, n) the Kirchhoff stress, Pa,
  !> and info(n) (J, eta, dissipation, hourglass energy, plastic flag,
  !> iterations). status(n) per element; ierr GRANBED_OK,
  !> GRANBED_ERR_POINT_FAILED or an argument error.
  subroutine granbed_hex_forces(props, volume_fix, kappa, n, reference, x, cp_inv, f, status, &
       ierr, tau, info)
    real(c_double), intent(in) :: props(GRANBED_VUMAT_NPROPS)
    logical, intent(in) :: volume_fix
    real(c_double), intent(in) :: kappa
    integer, intent(in) :: n
    real(c_double), intent(in) :: reference(GRANBED_HEX_REFERENCE_LEN, n), x(3, 8, n)
    real(c_double), intent(inout) :: cp_inv(6, n)
    real(c_double), intent(out) :: f(3, 8, n)
    integer(c_int32_t), intent(out) :: status(n), ierr
    real(c_double), intent(out), optional :: tau(6, n)
    type(granbed_point_info), intent(out), optional :: info(n)
    ierr = c_granbed_hex_forces(params_of(props), flag_of(volume_fix), kappa, int(n, c_size_t), &
         reference, x, cp_inv, f, tau, info, status)
  end subroutine granbed_hex_forces

  !> Projects the point p(3), m, on the bilinear quad(3, 4) (corners
  !> counter-clockwise seen from outside). ierr: GRANBED_OK,
  !> GRANBED_ERR_NON_FINITE or GRANBED_ERR_DEGENERATE.
  subroutine granbed_project_node(p, quad, projection, ierr)
    real(c_double), intent(in) :: p(3), quad(3, 4)
    type(granbed_quad_projection), intent(out) :: projection
    integer(c_int32_t), intent(out) :: ierr
    ierr = c_granbed_project_node_on_quad(p, quad, projection)
  end subroutine granbed_project_node

  !> The force that closes the predicted gap of constraint c in one step,
  !> shared by effective mass, with Coulomb friction (granbed_node_face_force
  !> of granbed.h): apply it as an extra external force at the corrector,
  !> x_{n+1} = x_pred + dt_squared f / m. weight: partition weight in (0, 1];
  !> friction: mu >= 0; dt_squared: dt_{n+1/2} dt_n > 0, s^2. A constraint
  !> with gap >= 0 gets a zero force. ierr: GRANBED_OK,
  !> GRANBED_ERR_NON_FINITE or GRANBED_ERR_INVALID_ARGUMENT (force not
  !> written).
  subroutine granbed_face_force(c, weight, friction, dt_squared, force, ierr)
    type(granbed_node_face), intent(in) :: c
    real(c_double), intent(in) :: weight, friction, dt_squared
    type(granbed_node_face_force), intent(inout) :: force
    integer(c_int32_t), intent(out) :: ierr
    ierr = c_granbed_node_face_force(c, weight, friction, dt_squared, force)
  end subroutine granbed_face_force

  !> props(1:8) of the standard granule type name ('A1' ... 'C3'); for an
  !> unknown name ierr is the C function's error and props are zero (the C
  !> struct was not written).
  subroutine granbed_preset_props(name, props, ierr)
    character(len=*), intent(in) :: name
    real(c_double), intent(out) :: props(GRANBED_VUMAT_NPROPS)
    integer(c_int32_t), intent(out) :: ierr
    type(granbed_material_params) :: p
    ierr = c_granbed_material_preset(trim(name)//c_null_char, p)
    if (ierr /= GRANBED_OK) then
      props = 0.0_c_double
      return
    end if
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

  !> A logical as the C ABI's 0/1 flag.
  pure function flag_of(yes) result(flag)
    logical, intent(in) :: yes
    integer(c_int32_t) :: flag
    flag = 0
    if (yes) flag = 1
  end function flag_of

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
