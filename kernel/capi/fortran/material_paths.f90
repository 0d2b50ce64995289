!> Drives a block of material points through granbed_vumat_block along the
!> paths of `granbed-cli point` CSV files (point k follows file k) and checks
!> that the Cauchy stress and the relative density equal the CLI's bit for
!> bit, and that granbed_update_points (the C ABI's own layout) gives the
!> same Cauchy stresses and relative densities; then checks the derived
!> constants against their formulas and that a bad Poisson ratio is named.
!>
!> usage: material_paths_f TYPE FILE.csv [FILE.csv ...]   (TYPE: A1 ... C3)
program material_paths_f
  use, intrinsic :: iso_c_binding, only: c_double, c_int32_t
  use, intrinsic :: iso_fortran_env, only: int64
  use granbed
  implicit none
  integer, parameter :: ncol = 24, max_rows = 100000
  ! CSV columns (1-based): f_xx 3, f_yy 4, f_zz 5, f_xy 6, sigma_xx..xy 14-19, eta 22, plastic 23
  integer, parameter :: nstatev = GRANBED_VUMAT_NSTATEV
  real(c_double), allocatable :: rows(:, :, :), defgrad(:, :), state_old(:, :), state_new(:, :), stress(:, :)
  real(c_double), allocatable :: f_points(:, :), cp_inv(:, :), stress_points(:, :)
  type(granbed_point_info), allocatable :: info(:)
  integer(c_int32_t), allocatable :: status(:), point_status(:)
  real(c_double) :: props(GRANBED_VUMAT_NPROPS), expect(6), derived(6), expect_derived(6), mu, lambda
  integer(c_int32_t) :: ierr
  integer :: nblock, nrows, k, r, u, ios, mismatches, plastic, point_mismatches
  character(len=512) :: arg, message
  ! VUMAT stress order 11 22 33 12 23 31 from the CSV's sigma xx yy zz yz xz xy.
  integer, parameter :: csv_of(6) = [14, 15, 16, 19, 17, 18]

  nblock = command_argument_count() - 1
  if (nblock < 1) stop 'usage: material_paths_f TYPE FILE.csv [FILE.csv ...]'
  call get_command_argument(1, arg)
  call granbed_preset_props(trim(arg), props, ierr)
  if (ierr /= GRANBED_OK) then
     print '(3a)', trim(arg), ': ', trim(granbed_message(ierr))
     stop 2
  end if

  allocate (rows(ncol, max_rows, nblock))
  nrows = -1
  do k = 1, nblock
     call get_command_argument(k + 1, arg)
     open (newunit=u, file=trim(arg), status='old', action='read')
     read (u, '(a)') message ! header
     r = 0
     do
        read (u, *, iostat=ios) rows(:, r + 1, k)
        if (ios /= 0) exit
        r = r + 1
     end do
     close (u)
     if (nrows >= 0 .and. r /= nrows) stop 'files differ in row count'
     nrows = r
  end do

  allocate (defgrad(nblock, 9), state_old(nblock, nstatev), state_new(nblock, nstatev), &
       stress(nblock, 6), status(nblock))
  allocate (f_points(9, nblock), cp_inv(6, nblock), stress_points(6, nblock), info(nblock), &
       point_status(nblock))
  state_old = 0 ! zero state variables = virgin state
  call granbed_state_init(nblock, cp_inv, ierr)
  if (ierr /= GRANBED_OK) stop 'granbed_state_init failed'
  mismatches = 0
  point_mismatches = 0
  plastic = 0
  do r = 1, nrows
     defgrad = 0
     do k = 1, nblock
        defgrad(k, 1) = rows(3, r, k)  ! F11
        defgrad(k, 2) = rows(4, r, k)  ! F22
        defgrad(k, 3) = rows(5, r, k)  ! F33
        defgrad(k, 4) = rows(6, r, k)  ! F12
     end do
     call granbed_vumat_block(nblock, nstatev, GRANBED_VUMAT_NPROPS, props, defgrad, state_old, &
          state_new, stress, status, ierr)
     if (ierr /= GRANBED_OK) then
        print '(a,i0,2a)', 'row ', r, ': ', trim(granbed_message(ierr))
        stop 1
     end if
     ! The same points through granbed_update_points: F row-major per point
     ! (the CSV's F is diagonal plus F12), stress in Voigt xx yy zz yz xz xy.
     f_points = 0
     do k = 1, nblock
        f_points([1, 5, 9, 2], k) = rows(3:6, r, k)
     end do
     call granbed_update_points(props, .true., nblock, f_points, cp_inv, GRANBED_STRESS_CAUCHY, &
          stress_points, info, point_status, ierr)
     if (ierr /= GRANBED_OK) then
        print '(a,i0,2a)', 'row ', r, ': granbed_update_points: ', trim(granbed_message(ierr))
        stop 1
     end if
     do k = 1, nblock
        if (any(transfer(stress_points(:, k), 0_int64, 6) /= &
             transfer(rows(14:19, r, k), 0_int64, 6)) .or. &
             transfer(info(k)%eta, 0_int64) /= transfer(rows(22, r, k), 0_int64)) &
             point_mismatches = point_mismatches + 1
     end do
     do k = 1, nblock
        expect = rows(csv_of, r, k)
        if (any(transfer(stress(k, :), 0_int64, 6) /= transfer(expect, 0_int64, 6)) .or. &
             transfer(state_new(k, 7), 0_int64) /= transfer(rows(22, r, k), 0_int64)) then
           mismatches = mismatches + 1
           if (mismatches <= 5) print '(a,i0,a,i0,2(a,es25.17))', 'point ', k, ' row ', r, &
                ': sigma_33 ', stress(k, 3), ' CLI ', expect(3)
        end if
        if (state_new(k, 8) == 1) plastic = plastic + 1
     end do
     state_old = state_new
  end do
  print '(a,i0,a,i0,a,i0,a,i0,a)', 'material_paths_f: ', nblock, ' points x ', nrows, ' rows (', &
       plastic, ' plastic updates): ', mismatches, ' mismatches'

  ! The derived constants, against their formulas written out here.
  call granbed_derived_props(props, derived, ierr)
  mu = props(1) / (2 * (1 + props(2)))
  lambda = props(1) * props(2) / ((1 + props(2)) * (1 - 2 * props(2)))
  expect_derived = [lambda, mu, lambda + 2 * mu / 3, lambda + 2 * mu, props(4) * props(7), &
       sqrt((lambda + 2 * mu) / (props(4) * props(7)))]
  if (ierr /= GRANBED_OK .or. any(abs(derived - expect_derived) > 1e-13_c_double * abs(expect_derived))) then
     print '(a,6es25.17)', 'FAIL: derived constants ', derived
     stop 1
  end if
  print '(a,f0.3,a)', 'material_paths_f: derived constants agree, c_d = ', derived(6), ' m/s'

  props(2) = 0.6_c_double
  call granbed_derived_props(props, derived, ierr)
  if (ierr /= GRANBED_ERR_INVALID_PARAMETER .or. any(derived /= 0)) then
     print '(a)', 'FAIL: nu = 0.6 gave derived constants'
     stop 1
  end if
  call granbed_check_props(props, ierr, message)
  print '(2a)', 'material_paths_f: ', trim(message)
  if (ierr /= GRANBED_ERR_INVALID_PARAMETER .or. index(message, 'poisson_ratio') == 0) then
     print '(a)', 'FAIL: nu = 0.6 was not rejected by name'
     stop 1
  end if
  print '(a,i0,a)', 'material_paths_f: granbed_update_points: ', point_mismatches, ' mismatches'
  if (mismatches /= 0 .or. point_mismatches /= 0 .or. plastic == 0) stop 1
end program material_paths_f
